#include "symoro/observer/momentum_observer.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace symoro::observer {

MomentumObserver::MomentumObserver(const robot::ModelHandle& model, const Eigen::VectorXd& phi,
                                   const MomentumObserverOptions& options)
    : model_(model), phi_(phi), rate_(options.inertia_rate), n_(model.nq()) {
  if (phi.size() != model.np())
    throw std::invalid_argument("MomentumObserver: phi has " + std::to_string(phi.size()) + " values, model " +
                                model.label() + " of " + model.robot() + " has " + std::to_string(model.np()) +
                                " base parameters");
  if (options.gain.size() == 0) {
    gain_ = Eigen::VectorXd::Constant(n_, options.default_gain);
  } else if (options.gain.size() == n_) {
    gain_ = options.gain;
  } else {
    throw std::invalid_argument("MomentumObserver: " + std::to_string(options.gain.size()) + " gains for " +
                                std::to_string(n_) + " joints");
  }
  for (int j = 0; j < n_; ++j)
    if (!(gain_(j) > 0) || !std::isfinite(gain_(j)))
      throw std::invalid_argument("MomentumObserver: the gain of joint " + std::to_string(j + 1) +
                                  " must be positive and finite");
  decay_.resize(n_);
  M_.setZero(n_, n_);
  M_prev_.setZero(n_, n_);
  if (rate_ == InertiaRate::derivatives) dM_.resize(n_, n_ * n_);
  for (Eigen::VectorXd* v : {&h_, &mdot_qd_, &qd_, &qd_prev_, &p_, &u_, &p_prev_, &u_prev_, &r_}) v->setZero(n_);
}

void MomentumObserver::evaluate(const double* q, const double* qd, const double* tau) {
  const bool derivatives = rate_ == InertiaRate::derivatives;
  if (derivatives)
    model_.inertia_derivatives(q, phi_.data(), M_.data(), dM_.data());
  else
    model_.inertia(q, phi_.data(), M_.data());
  model_.nonlinear_effects(q, qd, phi_.data(), h_.data());
  // p = M qd; with the derivatives, Mdot qd = sum_k qd_k (dM/dq_k) qd.
  for (int i = 0; i < n_; ++i) {
    double p = 0, m = 0;
    for (int j = 0; j < n_; ++j) {
      p += M_(i, j) * qd[j];
      if (!derivatives) continue;
      double row = 0;
      for (int k = 0; k < n_; ++k) row += dM_(i, k * n_ + j) * qd[k];
      m += row * qd[j];
    }
    p_(i) = p;
    mdot_qd_(i) = m;
    qd_(i) = qd[i];
  }
  for (int i = 0; i < n_; ++i) u_(i) = tau[i] - h_(i) + mdot_qd_(i);
}

void MomentumObserver::reset(const double* q, const double* qd, const double* tau) {
  evaluate(q, qd, tau);
  r_.setZero();
  started_ = true;
}

const Eigen::VectorXd& MomentumObserver::update(const double* q, const double* qd, const double* tau, double dt) {
  if (!started_) {
    reset(q, qd, tau);
    return r_;
  }
  if (!(dt > 0) || !std::isfinite(dt))
    throw std::invalid_argument("MomentumObserver::update: dt must be positive and finite, got " + std::to_string(dt));
  if (dt != last_dt_) {
    for (int j = 0; j < n_; ++j) decay_(j) = std::exp(-gain_(j) * dt);
    last_dt_ = dt;
  }
  p_prev_.swap(p_);
  u_prev_.swap(u_);
  qd_prev_.swap(qd_);
  M_prev_.swap(M_);
  evaluate(q, qd, tau);
  for (int j = 0; j < n_; ++j) {
    double mdot_qd_integral = 0;  // over the interval (difference form; else in u)
    if (rate_ == InertiaRate::difference)
      for (int i = 0; i < n_; ++i) mdot_qd_integral += (M_(j, i) - M_prev_(j, i)) * 0.5 * (qd_(i) + qd_prev_(i));
    const double mean_external = (p_(j) - p_prev_(j) - mdot_qd_integral) / dt - 0.5 * (u_(j) + u_prev_(j));
    r_(j) = decay_(j) * r_(j) + (1 - decay_(j)) * mean_external;
  }
  return r_;
}

}  // namespace symoro::observer
