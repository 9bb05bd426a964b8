// One run of the study (study/detail/run.hpp), for any model through its IdentificationModel.
#include "symoro/study/detail/run.hpp"

#include <algorithm>
#include <limits>

#include <fmt/format.h>

#include "symoro/error.hpp"
#include "symoro/excitation/quality.hpp"
#include "symoro/identify/physical_projection.hpp"
#include "symoro/identify/sdp_projection.hpp"
#include "symoro/preprocess/preprocess.hpp"

namespace symoro::study::detail {

// The paper's pre-CLIE step (Algorithm 1, lines 4-15): the all-pose audit of the OLS estimate
// and, when it is not PD, the conditional SDP projection. Fills the record's audit and route.
ClieStart pd_start(const identify::LeastSquaresResult& ls, const StudyOptions& options,
                   const identify::InertiaFunction& inertia, const identify::AuditDomain& domain, RunRecord& r) {
  const auto t = std::chrono::steady_clock::now();
  identify::ProjectionOptions po = options.projection;
  if (options.projection_metric == ProjectionMetric::information)
    po.metric = identify::information_metric(ls.information, options.information_ridge);
  const identify::ConditionalProjection cp = conditional_projection(inertia, ls.phi, domain, options.margins, po);
  const double conditional_wall = seconds_since(t);
  r.ols_lambda_min = cp.audit.lambda_min;
  r.ols_worst_pose = cp.audit.worst_pose;
  r.ols_pd = cp.audit.positive_definite();
  r.route = cp.projected ? "O-S-C" : "O-C";
  r.eps = cp.projected ? cp.eps : 0.0;
  r.sdp_feasible = cp.feasible;
  r.t_audit = cp.audit.wall;
  r.t_sdp = std::max(0.0, conditional_wall - cp.audit.wall);
  if (!cp.feasible) {
    // No margin gave a PD vector: the run has no SDP vector and no final one; its OLS stays in
    // the OLS cloud. Nothing downstream starts from a failed projection.
    r.clie_ran = false;
    std::string why;
    for (const identify::ProjectionResult& a : cp.attempts)
      why += fmt::format("{}eps {:g}: lambda_min {:.3g} ({})", why.empty() ? "" : "; ", a.eps, a.lambda_min, a.status);
    r.clie_termination = "not run: the SDP projection failed at every margin (" + why + ")";
  }
  return {cp.phi, cp.projected ? cp.attempts.back().lambda_min : r.ols_lambda_min};
}

// The physical path's pre-CLIE step when asked (StudyOptions::physical_start): the all-pose audit
// (for the record) and, when the OLS estimate has no consistent standard set, the nearest base
// vector that has one in the run's predicted-torque metric (physical_projection.hpp).
ClieStart physical_start(const identify::IdentificationModel& model, const identify::LeastSquaresResult& ls,
                         const StudyOptions& options, const identify::InertiaFunction& inertia,
                         const identify::AuditDomain& domain, RunRecord& r) {
  const identify::AuditResult a = audit_pd(inertia, ls.phi, domain, options.audit);
  r.ols_lambda_min = a.lambda_min;
  r.ols_worst_pose = a.worst_pose;
  r.ols_pd = a.positive_definite();
  r.t_audit = a.wall;
  const identify::PhysicalProjection p =
      model.physical_projection(ls.phi, torque_metric(ls, options.information_ridge), options.physical_clearance);
  r.physical = true;
  r.ols_consistent = p.consistent;
  r.ols_consistency = p.check.feasibility;
  r.route = p.projected ? "O-S-C" : "O-C";
  r.eps = p.projected ? options.physical_clearance : 0.0;
  r.sdp_feasible = p.feasible;
  r.t_sdp = p.wall;
  if (!p.feasible) {
    r.clie_ran = false;
    r.clie_termination = "not run: the physical projection failed (" + p.status + ")";
    return {p.phi, 0.0};
  }
  ClieStart start{p.phi, r.ols_lambda_min};
  if (p.projected) {  // the start's PD margin (no CLIE: the run's final one)
    const identify::AuditResult b = audit_pd(inertia, p.phi, domain, options.audit);
    start.lambda_min = b.lambda_min;
    r.t_audit += b.wall;
  }
  return start;
}

// One trajectory at one interval, from its log.
// sim: the run's closed loop, or nullptr (CLIE is skipped; `no_clie` says why).
RunRecord identify_run(const identify::IdentificationModel& model, const io::Log& log, const identify::ClosedLoop* sim,
                       const std::string& no_clie, double interval, const StudyOptions& options,
                       const identify::InertiaFunction& inertia, const identify::AuditDomain& domain) {
  RunRecord r;
  r.trajectory = log.meta.trajectory;
  r.interval = interval;
  auto t = std::chrono::steady_clock::now();
  const preprocess::Samples s = preprocess::preprocess(log, interval, options.preprocess);
  r.samples = static_cast<int>(s.time.size());
  r.edge_samples = s.report.edge_samples;
  const identify::Regression reg = model.stack_regression(s);
  identify::LeastSquaresResult ls;
  try {
    ls = least_squares(reg, options.least_squares);
  } catch (const std::invalid_argument& e) {
    throw DataError(log.meta.trajectory, 0, fmt::format("at {} ms: {}", interval * 1e3, e.what()));
  }
  r.kappa = ls.kappa;
  r.kappa_scaled = ls.kappa_scaled;
  const excitation::ExcitationQuality q =
      excitation::excitation_quality(reg.W, model.description().parameters, 3, false);
  r.log_det_scaled = q.log_det_scaled;
  for (const auto& [name, v] : q.weakest)
    r.weakest += fmt::format("{}{} {:+.2f}", r.weakest.empty() ? "" : ", ", name, v);
  r.phi_ols = ls.phi;
  r.std_ols = ls.std_dev;
  r.residual_rms = ls.residual_rms;
  r.weighted = ls.weighted;
  r.t_ols = seconds_since(t);

  const bool physical = options.consistency == Consistency::physical;
  const ClieStart start = physical && options.physical_start ? physical_start(model, ls, options, inertia, domain, r)
                                                             : pd_start(ls, options, inertia, domain, r);
  // Whether a vector has a consistent set (the physical path; its time counts as the SDP's).
  auto check = [&](const Eigen::VectorXd& phi, bool& consistent, double& margin) {
    const auto tc = std::chrono::steady_clock::now();
    const identify::ConsistencyResult k = model.physical_check(phi);
    consistent = k.ok();
    margin = k.feasibility;
    r.t_sdp += seconds_since(tc);
  };
  if (physical && !options.physical_start) {  // physical_start has checked the OLS vector already
    r.physical = true;
    check(ls.phi, r.ols_consistent, r.ols_consistency);
  }
  // The run's final vector (CLIE's, or the start without CLIE).
  auto check_final = [&](const Eigen::VectorXd& phi) {
    if (physical) check(phi, r.clie_consistent, r.clie_consistency);
  };
  if (!r.sdp_feasible) return r;  // no admissible start: no SDP vector, no final one (r says why)
  r.phi_sdp = start.phi;
  if (!sim) {
    // The chain ends at the SDP (or the admissible OLS estimate): that is the run's final vector.
    r.clie_ran = false;
    r.clie_termination = "not run: " + no_clie;
    r.phi_clie = r.phi_sdp;
    r.clie_lambda_min = start.lambda_min;
    r.clie_pd = true;
    check_final(r.phi_clie);
    return r;
  }
  t = std::chrono::steady_clock::now();
  identify::ClieOptions co = options.clie;
  co.preprocess = options.preprocess;
  if (co.std_bound > 0) co.scale = ls.std_dev;
  const identify::ClieResult c = clie(*sim, s, start.phi, co);
  r.t_clie = seconds_since(t);
  r.clie_success = c.success;
  r.clie_termination = c.start_divergence.diverged ? "start diverged: " + c.start_divergence.describe() : c.termination;
  r.clie_cost_initial = c.initial_cost;
  r.clie_cost_final = c.final_cost;
  r.clie_iterations = c.iterations;
  r.clie_rms = c.rms_final;
  if (c.success) {
    r.phi_clie = c.phi;
    const identify::AuditResult a = audit_pd(inertia, c.phi, domain, options.audit);
    r.clie_lambda_min = a.lambda_min;
    r.clie_pd = a.positive_definite();
    r.t_audit += a.wall;
    check_final(c.phi);
  }
  return r;
}

}  // namespace symoro::study::detail
