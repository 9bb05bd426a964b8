// Held-out validation (paper Table VII): the closed-loop simulated torque of a parameter vector
// against the measured torque of a trajectory not used for identification, at one interval;
// open loop (the model's torque on the measured motion) where the closed loop cannot be run.
//   RMSE = sqrt(mean over samples and joints of e^2)   (N m)
//   MNE  = mean over joints of |e_j| / |tau_m,j|        (2-norms over the samples)
#pragma once

#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include <fmt/format.h>

#include <Eigen/Core>

#include "symoro/identify/clie.hpp"
#include "symoro/identify/detail/closed_loop_model.hpp"
#include "symoro/study/result.hpp"

namespace symoro::study {

struct TorqueError {
  double rmse = std::numeric_limits<double>::quiet_NaN();
  double mne = std::numeric_limits<double>::quiet_NaN();
  Eigen::VectorXd rmse_joint;
};

inline TorqueError torque_error(const Eigen::MatrixXd& measured, const Eigen::MatrixXd& simulated) {
  TorqueError t;
  const Eigen::MatrixXd e = measured - simulated;
  t.rmse = std::sqrt(e.squaredNorm() / static_cast<double>(e.size()));
  t.rmse_joint = (e.colwise().squaredNorm() / static_cast<double>(e.rows())).cwiseSqrt().transpose();
  double sum = 0;
  for (Eigen::Index j = 0; j < e.cols(); ++j) sum += e.col(j).norm() / std::max(measured.col(j).norm(), 1e-300);
  t.mne = sum / static_cast<double>(e.cols());
  return t;
}

// The model's torque on the measured motion (open loop): ID(q, qd, qdd; phi) per sample.
template <class Model>
Eigen::MatrixXd open_loop_torque(const preprocess::Samples& s, const Eigen::VectorXd& phi) {
  using Vec = Eigen::Matrix<double, Model::nq, 1>;
  using Phi = Eigen::Matrix<double, Model::np, 1>;
  const Phi p = phi;
  Eigen::MatrixXd tau(s.q.rows(), Model::nq);
  Vec out;
  for (Eigen::Index i = 0; i < s.q.rows(); ++i) {
    Model::inverse_dynamics(Vec(s.q.row(i).transpose()), Vec(s.qd.row(i).transpose()), Vec(s.qdd.row(i).transpose()), p,
                            out);
    tau.row(i) = out.transpose();
  }
  return tau;
}

// The model's torque on the measured motion (open_loop_torque<Model> for a generated model).
using OpenLoopTorque = std::function<Eigen::MatrixXd(const preprocess::Samples&, const Eigen::VectorXd& phi)>;

// Held-out validation of the run's final vector (phi_clie) and the accepted one (phi_rescue).
// sim: the closed loop of the experiment, or nullptr (then open loop, `why_open` says why). A
// closed-loop simulation that diverges falls back to open loop for that vector, and the note
// names the vector, time, joint and reason: a validation never reports NaN without a reason.
// validation.cpp: compiled once for every model.
ValidationRecord validate_trajectory(const identify::ClosedLoop* sim, const OpenLoopTorque& open_loop,
                                     const preprocess::Samples& measured, const Eigen::VectorXd& phi_clie,
                                     const Eigen::VectorXd& phi_rescue, const identify::ClieOptions& options,
                                     const std::string& why_open = "");

// The same for a generated Model.
template <class Model>
ValidationRecord validate_trajectory(const identify::ClosedLoopSimulator<Model>* sim,
                                     const preprocess::Samples& measured, const Eigen::VectorXd& phi_clie,
                                     const Eigen::VectorXd& phi_rescue, const identify::ClieOptions& options,
                                     const std::string& why_open = "") {
  return validate_trajectory(sim, &open_loop_torque<Model>, measured, phi_clie, phi_rescue, options, why_open);
}

}  // namespace symoro::study
