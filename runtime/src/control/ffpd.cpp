#include "symoro/control/ffpd.hpp"

#include <stdexcept>

namespace symoro::control {

FfpdGains FfpdGains::from_bandwidth(double period, double tf, const Eigen::VectorXd& inertia,
                                    const Eigen::VectorXd& damping, const Eigen::VectorXd& bandwidth,
                                    const Eigen::VectorXd& damping_ratio) {
  FfpdGains g;
  g.period = period;
  g.pseudo_derivative_time = tf;
  g.inertia = inertia;
  g.damping = damping;
  g.kp = bandwidth.array().square();
  g.kv = 2.0 * damping_ratio.array() * bandwidth.array();
  return g;
}

FfpdController::FfpdController(const FfpdGains& gains) : g_(gains) {
  const Eigen::Index n = g_.inertia.size();
  if (g_.damping.size() != n || g_.kp.size() != n || g_.kv.size() != n)
    throw std::invalid_argument("FF+PD gains: inertia, damping, kp and kv must have one entry per joint");
  if (!(g_.period > 0) || !(g_.pseudo_derivative_time > 0))
    throw std::invalid_argument("FF+PD gains: period and pseudo-derivative time must be positive");
  const double T = g_.period, Tf = g_.pseudo_derivative_time;
  a_ = (2 * Tf - T) / (2 * Tf + T);
  b_ = 2 / (2 * Tf + T);
  q_prev_ = Eigen::VectorXd::Zero(n);
  qd_hat_ = Eigen::VectorXd::Zero(n);
  u_ = Eigen::VectorXd::Zero(n);
}

void FfpdController::reset(const Eigen::VectorXd& q) {
  q_prev_ = q;
  qd_hat_.setZero();
}

const Eigen::VectorXd& FfpdController::update(const Eigen::VectorXd& q, const Eigen::VectorXd& q_ref,
                                              const Eigen::VectorXd& qd_ref, const Eigen::VectorXd& qdd_ref) {
  qd_hat_ = a_ * qd_hat_ + b_ * (q - q_prev_);
  q_prev_ = q;
  u_ = ffpd_command(g_, q, qd_hat_, q_ref, qd_ref, qdd_ref);
  return u_;
}

Eigen::VectorXd ffpd_command(const FfpdGains& g, const Eigen::VectorXd& q, const Eigen::VectorXd& qd_hat,
                             const Eigen::VectorXd& q_ref, const Eigen::VectorXd& qd_ref,
                             const Eigen::VectorXd& qdd_ref) {
  return g.inertia.cwiseProduct(g.kv.cwiseProduct(qd_ref - qd_hat) + g.kp.cwiseProduct(q_ref - q) + qdd_ref) +
         g.damping.cwiseProduct(qd_ref);
}

}  // namespace symoro::control
