// The simulated arm: the robot's full generated model (forward dynamics: products of inertia,
// rotor inertia, viscous friction) plus the twin's switchable physical effects, integrated
// with classical Runge-Kutta 4 while the motor torques are held constant.
//
// Effects on the mechanics: smooth Coulomb and Stribeck friction, a constant unmeasured torque
// offset, and backlash. With backlash a joint's rotor becomes its own body: the rotor (rotor
// inertia, viscous and Coulomb friction) drives the link through a dead zone of the given width
// and a stiff, lightly damped gear mesh beyond it; the link side uses the model without that
// joint's rotor inertia and viscous friction.
#pragma once

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Core>
#include <Eigen/Cholesky>

#include "symoro/twin/config.hpp"
#include "symoro/twin/truth.hpp"

namespace symoro::twin {

template <class Model>
class Plant {
 public:
  static constexpr int n = Model::nq;
  using Vec = Eigen::Matrix<double, n, 1>;
  using Phi = Eigen::Matrix<double, Model::np, 1>;
  // q, qd (links), then qm, qdm (rotors; used by backlash joints only).
  using State = Eigen::Matrix<double, 4 * n, 1>;

  Plant(const Truth<Model>& truth, const TwinConfig& c, const Vec& q0)
      : phi_(truth.phi), phi_links_(truth.phi_links), max_step_(c.max_step) {
    const Effects& e = c.effects;
    fv_ = c.viscous;
    ia_ = c.rotor_inertia;
    fc_ = e.coulomb ? Vec(e.coulomb_torque) : Vec::Zero();
    fs_ = e.stribeck ? Vec(e.stribeck_torque) : Vec::Zero();
    v_eps_ = e.coulomb_smoothing_velocity;
    v_s_ = e.stribeck_velocity;
    offset_ = e.torque_offset ? Vec(e.offset_torque) : Vec::Zero();
    friction_ = e.coulomb || e.stribeck;
    half_width_.setZero();
    stiffness_.setZero();
    mesh_damping_.setZero();
    backlash_ = false;
    if (e.backlash) {
      // Mesh stiffness from the rotor-link pair's natural frequency at the start pose:
      // w^2 = k (1/IA + (M^-1)_jj), M the link-side inertia (its inverse diagonal is the
      // joint's mobility with the other joints free, which bounds the coupled modes).
      Eigen::Matrix<double, n, n> M;
      Model::inertia(q0, phi_links_, M);
      const Eigen::Matrix<double, n, n> mobility = M.llt().solve(Eigen::Matrix<double, n, n>::Identity());
      const double w = 2 * 3.14159265358979323846 * e.backlash_frequency;
      for (int j = 0; j < n; ++j) {
        if (!(e.backlash_width(j) > 0)) continue;
        if (!(ia_(j) > 0))
          throw DataError(c.path, 0, "backlash on joint " + std::to_string(j + 1) + " needs a positive rotor inertia");
        if (!(M(j, j) > 0) || !std::isfinite(mobility(j, j)))
          throw DataError(c.path, 0, "backlash on joint " + std::to_string(j + 1) + ": the link side has no inertia");
        backlash_ = true;
        half_width_(j) = e.backlash_width(j) / 2;
        const double reduced = 1 / (1 / ia_(j) + mobility(j, j));
        stiffness_(j) = reduced * w * w;
        mesh_damping_(j) = 2 * e.backlash_damping_ratio * std::sqrt(stiffness_(j) * reduced);
      }
      // RK4 resolves an oscillation well when h w <= 0.3 (amplitude error ~ (h w)^6 / 144 per
      // step): the mesh mode sets the step when it is faster than the rigid dynamics.
      if (backlash_) max_step_ = std::min(max_step_, 0.3 / w);
    }
    x_.setZero();
    x_.template segment<n>(0) = q0;
    x_.template segment<n>(2 * n) = q0;
  }

  const State& state() const { return x_; }
  void set_state(const State& x) { x_ = x; }
  auto q() const { return x_.template segment<n>(0); }
  auto qd() const { return x_.template segment<n>(n); }
  bool has_backlash() const { return backlash_; }
  double max_step() const { return max_step_; }
  auto rotor_q() const { return x_.template segment<n>(2 * n); }

  // Advances by dt with the motor torques held, in equal RK4 steps no longer than max_step.
  void advance(double dt, const Vec& motor_torque) {
    if (dt <= 0) return;
    const int steps = static_cast<int>(std::ceil(dt / max_step_ - 1e-9));
    const double h = dt / steps;
    State k1, k2, k3, k4;
    for (int s = 0; s < steps; ++s) {
      derivative(x_, motor_torque, k1);
      derivative(x_ + (h / 2) * k1, motor_torque, k2);
      derivative(x_ + (h / 2) * k2, motor_torque, k3);
      derivative(x_ + h * k3, motor_torque, k4);
      x_ += (h / 6) * (k1 + 2 * k2 + 2 * k3 + k4);
    }
  }

  // The friction beyond viscous: smooth Coulomb plus Stribeck, odd in the velocity.
  double extra_friction(int j, double v) const {
    if (!friction_) return 0;
    const double level = fc_(j) + fs_(j) * std::exp(-(v / v_s_) * (v / v_s_));
    return level * std::tanh(v / v_eps_);
  }

  void derivative(const State& x, const Vec& motor_torque, State& dx) const {
    const auto q = x.template segment<n>(0);
    const auto qd = x.template segment<n>(n);
    Vec tau;
    dx.setZero();
    for (int j = 0; j < n; ++j) {
      const double drive = motor_torque(j) + offset_(j);
      if (half_width_(j) > 0) {
        const double qm = x(2 * n + j), qdm = x(3 * n + j);
        const double delta = qm - q(j), hw = half_width_(j);
        // A dead zone with rounded corners (radius eps = hw / 20): a kink would cost RK4 its
        // order at every contact; the smooth one keeps it while the play stays the same.
        const double eps = hw / 20, up = delta - hw, down = delta + hw;
        const double ru = std::sqrt(up * up + eps * eps), rd = std::sqrt(down * down + eps * eps);
        const double deflection = 0.5 * (up + ru) + 0.5 * (down - rd);
        const double contact = 0.5 * (1 + up / ru) + 0.5 * (1 - down / rd);  // d deflection / d delta, in [0, 1]
        const double mesh = stiffness_(j) * deflection + mesh_damping_(j) * contact * (qdm - qd(j));
        tau(j) = mesh;
        dx(2 * n + j) = qdm;
        dx(3 * n + j) = (drive - fv_(j) * qdm - extra_friction(j, qdm) - mesh) / ia_(j);
      } else {
        tau(j) = drive - extra_friction(j, qd(j));
      }
    }
    Vec qdd;
    Model::forward_dynamics(q, qd, tau, backlash_ ? phi_links_ : phi_, qdd);
    dx.template segment<n>(0) = qd;
    dx.template segment<n>(n) = qdd;
  }

  // Mechanical energy of the rigid plant (no backlash): kinetic 1/2 qd' M qd plus `potential`.
  double kinetic_energy() const {
    Eigen::Matrix<double, n, n> M;
    Model::inertia(q(), phi_, M);
    return 0.5 * qd().dot(M * qd());
  }

 private:
  Phi phi_, phi_links_;
  double max_step_;
  Vec fv_, ia_, fc_, fs_, offset_, half_width_, stiffness_, mesh_damping_;
  double v_eps_ = 0.01, v_s_ = 0.05;
  bool friction_ = false, backlash_ = false;
  State x_;
};

}  // namespace symoro::twin
