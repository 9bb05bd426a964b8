#include "symoro/twin/tracking_bound.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace symoro::twin {

namespace {

// The scalar loop of one joint with zero reference: plant m qdd + c qd = u + w, controller
// u_k = -m (K_V qd_hat_k + K_P y_k) on the measurement y_k = q(t_k) + noise_k, applied at
// t_k + d and held. Returns q(t) on a fine grid (h) over `span` seconds.
struct ScalarLoop {
  double m, c, kp, kv, T, d, a, b;

  std::vector<double> respond(double impulse_time, double noise_at_0, double span, double h) const {
    const int steps_per_period = static_cast<int>(std::lround(T / h));
    const int delay_steps = static_cast<int>(std::lround(d / h));
    const int impulse_step = static_cast<int>(std::lround(impulse_time / h));
    const int total = static_cast<int>(span / h);
    std::vector<double> q(total + 1, 0.0);
    double x = 0, v = 0, u_applied = 0, u_next = 0, qd_hat = 0, y_prev = 0;
    for (int s = 0; s <= total; ++s) {
      if (s == impulse_step) v += 1.0 / m;  // unit torque impulse
      if (s % steps_per_period == 0) {
        const double y = x + (s == 0 ? noise_at_0 : 0.0);
        qd_hat = a * qd_hat + b * (y - y_prev);
        y_prev = y;
        u_next = -m * (kv * qd_hat + kp * y);
      }
      if (s % steps_per_period == delay_steps) u_applied = u_next;
      q[s] = x;
      // Exact step of m vdot + c v = u over h (u held).
      const double F = u_applied;
      if (c > 0) {
        const double vinf = F / c, decay = std::exp(-c * h / m);
        x += vinf * h + (v - vinf) * (m / c) * (1 - decay);
        v = vinf + (v - vinf) * decay;
      } else {
        x += v * h + 0.5 * F / m * h * h;
        v += F / m * h;
      }
    }
    return q;
  }
};

ScalarLoop scalar_loop(const TwinConfig& c, int j) {
  const ControllerConfig& k = c.controller;
  ScalarLoop l;
  l.m = k.realization_inertia(j);
  l.c = k.realization_damping(j);
  l.kp = k.bandwidth(j) * k.bandwidth(j);
  l.kv = 2 * k.damping_ratio(j) * k.bandwidth(j);
  l.T = k.period;
  l.d = k.communication_delay;
  const double Tf = k.pseudo_derivative_time;
  l.a = (2 * Tf - l.T) / (2 * Tf + l.T);
  l.b = 2 / (2 * Tf + l.T);
  return l;
}

}  // namespace

LoopGains loop_gains(const TwinConfig& c, int j) {
  const ScalarLoop loop = scalar_loop(c, j);
  const double h = loop.T / 100, span = 40.0 / c.controller.bandwidth(j) + 0.5;
  LoopGains g;
  for (int phase = 0; phase < 10; ++phase) {
    const auto q = loop.respond(phase * loop.T / 10, 0.0, span, h);
    double l1 = 0;
    for (double x : q) l1 += std::abs(x) * h;
    g.torque = std::max(g.torque, l1);
  }
  const auto q = loop.respond(-1.0, 1.0, span, h);
  const int per = static_cast<int>(std::lround(loop.T / h));
  for (size_t s = 0; s < q.size(); s += per) {
    double peak = 0;
    for (size_t i = s; i < std::min(q.size(), s + per); ++i) peak = std::max(peak, std::abs(q[i]));
    g.measurement += peak;
  }
  return g;
}

Eigen::VectorXd tracking_error_bound(const TwinConfig& c, const Eigen::VectorXd& sup_w) {
  const int n = static_cast<int>(sup_w.size());
  Eigen::VectorXd bound(n);
  for (int j = 0; j < n; ++j) {
    const LoopGains g = loop_gains(c, j);
    const Servo& s = c.servos[j];
    const double lsb = 2 * 3.14159265358979323846 / s.encoder_counts;
    const double meas = lsb * (0.5 + (c.effects.sensor_noise ? 5 * c.effects.encoder_noise : 0.0));
    bound(j) = g.torque * sup_w(j) + g.measurement * meas;
  }
  return bound;
}

}  // namespace symoro::twin
