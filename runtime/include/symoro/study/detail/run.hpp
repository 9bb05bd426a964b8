// One run of the identification study: one trajectory's log at one sampling interval, through
// OLS, the all-pose audit, the pre-CLIE projection (the paper's conditional PD projection, or
// the physical one) and CLIE, into a RunRecord. Used by the study; internals (namespace detail),
// compiled once for every model (study/run.cpp).
#pragma once

#include <chrono>
#include <string>

#include <Eigen/Core>
#include <fmt/format.h>

#include "symoro/identify/clie.hpp"
#include "symoro/identify/identification_model.hpp"
#include "symoro/identify/least_squares.hpp"
#include "symoro/identify/pd_audit.hpp"
#include "symoro/identify/sdp_projection.hpp"
#include "symoro/study/options.hpp"
#include "symoro/study/result.hpp"
#include "symoro/io/log.hpp"

namespace symoro::study {

namespace detail {

inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The run's predicted-torque metric W'W / rows (the information matrix is W'W / sigma^2,
// sigma^2 = |r|^2 / (rows - np)): distances in it are RMS changes of the fitted torque, N m.
inline Eigen::MatrixXd torque_metric(const identify::LeastSquaresResult& ls, double ridge) {
  return identify::information_metric(ls.information, ridge) *
         (ls.residual_rms * ls.residual_rms / static_cast<double>(ls.rows - ls.phi.size()));
}

// CLIE's starting point, with its PD margin.
struct ClieStart {
  Eigen::VectorXd phi;
  double lambda_min = 0;
};

// The paper's pre-CLIE step (Algorithm 1, lines 4-15): the all-pose audit of the OLS estimate
// and, when it is not PD, the conditional SDP projection. Fills the record's audit and route.
ClieStart pd_start(const identify::LeastSquaresResult& ls, const StudyOptions& options,
                   const identify::InertiaFunction& inertia, const identify::AuditDomain& domain, RunRecord& r);

// The physical path's pre-CLIE step when asked (StudyOptions::physical_start): the all-pose audit
// (for the record) and, when the OLS estimate has no consistent standard set, the nearest base
// vector that has one in the run's predicted-torque metric (physical_projection.hpp).
ClieStart physical_start(const identify::IdentificationModel& model, const identify::LeastSquaresResult& ls,
                         const StudyOptions& options, const identify::InertiaFunction& inertia,
                         const identify::AuditDomain& domain, RunRecord& r);

// One trajectory at one interval, from its log.
// sim: the run's closed loop, or nullptr (CLIE is skipped; `no_clie` says why).
RunRecord identify_run(const identify::IdentificationModel& model, const io::Log& log, const identify::ClosedLoop* sim,
                       const std::string& no_clie, double interval, const StudyOptions& options,
                       const identify::InertiaFunction& inertia, const identify::AuditDomain& domain);

}  // namespace detail

}  // namespace symoro::study
