// The paper's joint-space controller (eq. ffpd_command): feedforward plus PD with pseudo
// differentiation, per joint,
//   u = M_hat [ K_V (qd_ref + K_P/K_V (q_ref - q) - qd_hat) + qdd_ref ] + D_hat qd_ref,
//   qd_hat = s / (1 + Tf s) q   (discretized with Tustin's rule at the control period).
// M_hat and D_hat are realization parameters (a joint-level fit), not the identified model.
// Plain double code, shared by the digital twin and the real arm's control loop.
#pragma once

#include <Eigen/Core>

namespace symoro::control {

struct FfpdGains {
  double period = 0.001;                  // s
  double pseudo_derivative_time = 0.002;  // s, Tf
  Eigen::VectorXd inertia, damping;       // M_hat (kg m^2), D_hat (N m s/rad)
  Eigen::VectorXd kp, kv;                 // 1/s^2, 1/s

  // K_P = w^2 and K_V = 2 zeta w: critically damped error dynamics for zeta = 1.
  static FfpdGains from_bandwidth(double period, double tf, const Eigen::VectorXd& inertia,
                                  const Eigen::VectorXd& damping, const Eigen::VectorXd& bandwidth,
                                  const Eigen::VectorXd& damping_ratio);
};

// The law for one cycle given the velocity estimate qd_hat (FfpdController's own, or a log's):
// u = M_hat [K_V (qd_ref - qd_hat) + K_P (q_ref - q) + qdd_ref] + D_hat qd_ref.
Eigen::VectorXd ffpd_command(const FfpdGains& g, const Eigen::VectorXd& q, const Eigen::VectorXd& qd_hat,
                             const Eigen::VectorXd& q_ref, const Eigen::VectorXd& qd_ref,
                             const Eigen::VectorXd& qdd_ref);

class FfpdController {
 public:
  explicit FfpdController(const FfpdGains& gains);

  // Starts at rest at q: the pseudo-derivative's state is set so that qd_hat = 0.
  void reset(const Eigen::VectorXd& q);
  // One control cycle with the measured q; returns the joint torque command u (N m).
  const Eigen::VectorXd& update(const Eigen::VectorXd& q, const Eigen::VectorXd& q_ref, const Eigen::VectorXd& qd_ref,
                                const Eigen::VectorXd& qdd_ref);
  // The pseudo-differentiated velocity of the last update.
  const Eigen::VectorXd& velocity() const { return qd_hat_; }
  const FfpdGains& gains() const { return g_; }

 private:
  FfpdGains g_;
  double a_ = 0, b_ = 0;  // Tustin: qd_hat_k = a qd_hat_{k-1} + b (q_k - q_{k-1})
  Eigen::VectorXd q_prev_, qd_hat_, u_;
};

}  // namespace symoro::control
