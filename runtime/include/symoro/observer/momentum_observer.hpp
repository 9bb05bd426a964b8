// The generalized-momentum observer (De Luca and Mattone, 2003): the residual
//   r = K (p(t) - p(0) - integral of (tau + C(q, qd)' qd - g(q) - f(qd) + r) dt),  p = M(q) qd,
// from a model and its parameters alone, with no joint acceleration. In continuous time
// dr/dt = K (tau_ext - r): r is the external torque at each joint through a first-order low-pass
// of corner K, decoupled across joints, which is why it detects and isolates a collision.
//
// C' qd = Mdot qd - C qd, and the model's h(q, qd) = C qd + g + friction, so the observer's input
// is u = tau - h + Mdot qd. Friction and every other effect the model holds are in h: only what
// the model does not hold is left.
//
// Discretized for logged samples (any sampling interval, not only 1 ms): over one interval the
// momentum changes by the integral of u + tau_ext; with the trapezoid rule,
//   e_k = p_k - p_{k-1} - dt (u_k + u_{k-1}) / 2   (dt times the interval's mean tau_ext),
//   r_k = a r_{k-1} + (1 - a) e_k / dt,             a = exp(-K dt),
// the first-order filter's exact step for a torque held over the interval, stable at any K dt.
// The integral of Mdot qd takes one of two forms (InertiaRate):
//   derivatives  Mdot qd = sum_k qd_k (dM/dq_k) qd from the model's inertia derivatives, by the
//                trapezoid rule with the rest of u;
//   difference   (M_k - M_{k-1}) (qd_k + qd_{k-1}) / 2: as accurate (second order; with the
//                momentum's change it is exactly the interval's mean M times the change of qd),
//                and it needs M alone, a tenth of the derivatives' cost on a 7-joint arm.
#pragma once

#include <Eigen/Core>

#include "symoro/robot/model_handle.hpp"

namespace symoro::observer {

enum class InertiaRate { difference, derivatives };

struct MomentumObserverOptions {
  // K, 1/s per joint (the residual's corner is K / 2 pi Hz); empty: `default_gain` on every joint.
  // Higher: faster detection, more of the model's error and the sensors' noise in r.
  Eigen::VectorXd gain;
  double default_gain = 50;
  InertiaRate inertia_rate = InertiaRate::difference;
};

class MomentumObserver {
 public:
  // `phi`: the model's base parameters (an identification's, or its nominal ones).
  MomentumObserver(const robot::ModelHandle& model, const Eigen::VectorXd& phi,
                   const MomentumObserverOptions& options = {});

  // Starts (or restarts) at this sample: r = 0. Arrays of nq doubles.
  void reset(const double* q, const double* qd, const double* tau);
  // The next sample, dt seconds after the last (dt > 0): r, nq values. Allocates nothing.
  const Eigen::VectorXd& update(const double* q, const double* qd, const double* tau, double dt);

  const Eigen::VectorXd& residual() const { return r_; }
  const Eigen::VectorXd& momentum() const { return p_; }  // M(q) qd at the last sample
  const Eigen::VectorXd& gain() const { return gain_; }
  int nq() const { return n_; }
  bool started() const { return started_; }

 private:
  // p and u at (q, qd, tau) into p_, u_.
  void evaluate(const double* q, const double* qd, const double* tau);

  robot::ModelHandle model_;
  Eigen::VectorXd phi_, gain_;
  InertiaRate rate_;
  int n_ = 0;
  bool started_ = false;
  double last_dt_ = -1;
  Eigen::VectorXd decay_;  // exp(-K dt) at last_dt_
  // nq x nq, and nq x (nq nq): the blocks dM/dq_k side by side (InertiaRate::derivatives only)
  Eigen::MatrixXd M_, M_prev_, dM_;
  Eigen::VectorXd h_, mdot_qd_, qd_, qd_prev_, p_, u_, p_prev_, u_prev_, r_;
};

}  // namespace symoro::observer
