// Held-out validation (validation.hpp) for any model: its closed loop, else its open-loop torque.
#include "symoro/study/validation.hpp"

#include <algorithm>

namespace symoro::study {

ValidationRecord validate_trajectory(const identify::ClosedLoop* sim, const OpenLoopTorque& open_loop,
                                     const preprocess::Samples& measured, const Eigen::VectorXd& phi_clie,
                                     const Eigen::VectorXd& phi_rescue, const identify::ClieOptions& options,
                                     const std::string& why_open) {
  ValidationRecord v;
  v.interval = measured.interval;
  v.time = measured.time;
  v.tau_measured = measured.tau;
  v.q = measured.q;
  v.qd = measured.qd;
  v.qdd = measured.qdd;
  v.kind = sim ? "closed-loop" : "open-loop";
  if (!sim) v.note = "open loop: " + why_open;
  const Eigen::Index n = measured.tau.cols();
  auto run = [&](const char* which, const Eigen::VectorXd& phi, Eigen::MatrixXd& tau, double& rmse, double& mne,
                 Eigen::VectorXd& joint) {
    rmse = mne = std::numeric_limits<double>::quiet_NaN();
    if (phi.size() == 0) {
      tau = Eigen::MatrixXd::Constant(measured.tau.rows(), n, std::numeric_limits<double>::quiet_NaN());
      joint = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN());
      return;
    }
    identify::Divergence why;
    if (!sim || !simulated_samples(*sim, measured, phi, options, tau, &why)) {
      if (sim) {
        v.kind = "open-loop";
        v.note += fmt::format("{}the closed loop of the {} vector {}; open-loop values", v.note.empty() ? "" : "; ",
                              which, why.describe());
      }
      tau = open_loop(measured, phi);
    }
    const TorqueError e = torque_error(measured.tau, tau);
    rmse = e.rmse;
    mne = e.mne;
    joint = e.rmse_joint;
  };
  run("final", phi_clie, v.tau_clie, v.rmse_clie, v.mne_clie, v.rmse_joint_clie);
  run("accepted", phi_rescue, v.tau_rescue, v.rmse_rescue, v.mne_rescue, v.rmse_joint_rescue);
  if (v.rmse_joint_rescue.size() == n) {
    const Eigen::VectorXd rms =
        (measured.tau.colwise().squaredNorm() / std::max<double>(1, measured.tau.rows())).cwiseSqrt().transpose();
    v.nrmse_joint_rescue = v.rmse_joint_rescue.cwiseQuotient(rms.cwiseMax(1e-300));
  }
  return v;
}

}  // namespace symoro::study
