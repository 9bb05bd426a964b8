// A bound on the twin's tracking error under FF+PD, derived joint by joint.
//
// Write the true joint torque as tau_j = M_hat_j qdd_j + D_hat_j qd_j + w_j: w_j is everything
// the realization model leaves out (gravity, coupling, the error in M_hat and D_hat, friction
// beyond viscous, offsets). The controller cancels M_hat qdd_ref + D_hat qd_ref, so the error
// e_j = q_ref_j - q_j obeys the sampled loop of a plant M_hat_j qdd + D_hat_j qd = u + w with
// the exact controller (Tustin pseudo-derivative, communication delay, sample and hold), driven
// by w_j and by the measurement errors (encoder quantization and noise) and current
// quantization. For a linear loop, sup|e| <= G_w sup|w| + G_m sup|measurement error|, where
// G_w is the L1 norm of the loop's response to a unit torque impulse (maximized over the
// impulse's phase in the period) and G_m the sum over periods of the peak response to a unit
// measurement error in one sample. Both come from simulating that scalar loop exactly.
// sup|w_j| is evaluated along the reference with the twin's true parameters (q close to
// q_ref: the bound neglects the second-order change of w with the error). Backlash is outside
// this model.
#pragma once

#include <Eigen/Core>

#include "symoro/trajectory/trajectory.hpp"
#include "symoro/twin/config.hpp"

namespace symoro::twin {

struct LoopGains {
  double torque = 0;       // rad per N m of sup|w|
  double measurement = 0;  // rad per rad of sup|measurement error|
};

// The gains of joint j's linear sampled loop (0-based j).
LoopGains loop_gains(const TwinConfig& c, int j);

// sup_t |w_j(t)| along the reference, given the torque the true model needs there.
// needed(t) -> true joint torques at (q_ref, qd_ref, qdd_ref)(t); sampled every `step`.
template <class Needed>
Eigen::VectorXd unmodeled_torque(const TwinConfig& c, const trajectory::Trajectory& t, Needed&& needed,
                                 double step = 0.001) {
  const int n = t.joints();
  Eigen::VectorXd q(n), qd(n), qdd(n), worst = Eigen::VectorXd::Zero(n);
  const int K = static_cast<int>(t.duration() / step);
  for (int k = 0; k <= K; ++k) {
    t.evaluate(k * step, q, qd, qdd);
    const Eigen::VectorXd tau = needed(q, qd, qdd);
    const Eigen::VectorXd w =
        tau - c.controller.realization_inertia.cwiseProduct(qdd) - c.controller.realization_damping.cwiseProduct(qd);
    worst = worst.cwiseMax(w.cwiseAbs());
  }
  const Effects& e = c.effects;
  for (int j = 0; j < n; ++j) {
    if (e.coulomb) worst(j) += e.coulomb_torque(j);
    if (e.stribeck) worst(j) += e.stribeck_torque(j);
    if (e.torque_offset) worst(j) += std::abs(e.offset_torque(j));
    if (e.contact && j == e.contact_joint - 1) worst(j) += std::abs(e.contact_torque);
    // Half a current step of quantization and a 5-sigma current noise act like torque.
    const Servo& s = c.servos[j];
    worst(j) += s.torque_constant * (s.current_unit / 2 + (e.sensor_noise ? 5 * e.current_noise : 0.0));
  }
  return worst;
}

// The bound per joint (rad) for a trajectory, from sup|w| and the loop gains.
Eigen::VectorXd tracking_error_bound(const TwinConfig& c, const Eigen::VectorXd& sup_w);

}  // namespace symoro::twin
