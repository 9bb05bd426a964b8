// Held-out validation (paper Table VII): the closed-loop simulated torque of a parameter vector
// against the measured torque of a trajectory not used for identification, at one interval.
//   RMSE = sqrt(mean over samples and joints of e^2)   (N m)
//   MNE  = mean over joints of |e_j| / |tau_m,j|        (2-norms over the samples)
#pragma once

#include <cmath>
#include <limits>

#include <Eigen/Core>

#include "symoro/identify/clie.hpp"
#include "symoro/identify/clie_model.hpp"
#include "symoro/identify/closed_loop_model.hpp"
#include "symoro/identify/study_result.hpp"

namespace symoro::identify {

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

template <class Model>
ValidationRecord validate_trajectory(const ClosedLoopSimulator<Model>& sim, const preprocess::Samples& measured,
                                     const Eigen::VectorXd& phi_clie, const Eigen::VectorXd& phi_rescue,
                                     const ClieOptions& options) {
  ValidationRecord v;
  v.interval = measured.interval;
  v.time = measured.time;
  v.tau_measured = measured.tau;
  v.q = measured.q;
  v.qd = measured.qd;
  v.qdd = measured.qdd;
  Divergence why;
  const Eigen::Index n = measured.tau.cols();
  auto run = [&](const Eigen::VectorXd& phi, Eigen::MatrixXd& tau, double& rmse, double& mne, Eigen::VectorXd& joint) {
    if (phi.size() == 0 || !simulated_samples<Model>(sim, measured, phi, options, tau, &why)) {
      tau = Eigen::MatrixXd::Constant(measured.tau.rows(), n, std::numeric_limits<double>::quiet_NaN());
      joint = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN());
      return;
    }
    const TorqueError e = torque_error(measured.tau, tau);
    rmse = e.rmse;
    mne = e.mne;
    joint = e.rmse_joint;
  };
  v.rmse_clie = v.mne_clie = v.rmse_rescue = v.mne_rescue = std::numeric_limits<double>::quiet_NaN();
  run(phi_clie, v.tau_clie, v.rmse_clie, v.mne_clie, v.rmse_joint_clie);
  run(phi_rescue, v.tau_rescue, v.rmse_rescue, v.mne_rescue, v.rmse_joint_rescue);
  return v;
}

}  // namespace symoro::identify
