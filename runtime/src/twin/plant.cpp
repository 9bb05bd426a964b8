#include "symoro/twin/plant.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include <Eigen/Cholesky>

#include "symoro/error.hpp"

namespace symoro::twin {

Plant::Plant(robot::ModelHandle model, const Truth& truth, const TwinConfig& c, const Eigen::VectorXd& q0)
    : model_(std::move(model)), n_(model_.nq()), phi_(truth.phi), phi_links_(truth.phi_links), max_step_(c.max_step) {
  const int n = n_;
  if (q0.size() != n || phi_.size() != model_.np() || phi_links_.size() != model_.np())
    throw DataError(c.path, 0, "the twin's plant: start posture or truth not sized for robot '" + model_.robot() + "'");
  const Effects& e = c.effects;
  effects_ = e;
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  fv_ = c.viscous;
  ia_ = c.rotor_inertia;
  fc_ = e.coulomb ? e.coulomb_torque : zero;
  fs_ = e.stribeck ? e.stribeck_torque : zero;
  v_eps_ = e.coulomb_smoothing_velocity;
  v_s_ = e.stribeck_velocity;
  offset_ = e.torque_offset ? e.offset_torque : zero;
  friction_ = e.coulomb || e.stribeck;
  half_width_ = stiffness_ = mesh_damping_ = zero;
  if (e.backlash) {
    // Mesh stiffness from the rotor-link pair's natural frequency at the start pose:
    // w^2 = k (1/IA + (M^-1)_jj), M the link-side inertia (its inverse diagonal is the
    // joint's mobility with the other joints free, which bounds the coupled modes).
    Eigen::MatrixXd M(n, n);
    model_.inertia(q0.data(), phi_links_.data(), M.data());
    const Eigen::MatrixXd mobility = M.llt().solve(Eigen::MatrixXd::Identity(n, n));
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
  x_ = Eigen::VectorXd::Zero(4 * n);
  x_.head(n) = q0;
  x_.segment(2 * n, n) = q0;
  k1_ = k2_ = k3_ = k4_ = xt_ = x_;
  tau_ = zero;
}

void Plant::advance(double dt, const Eigen::VectorXd& motor_torque) {
  if (dt <= 0) return;
  const int steps = static_cast<int>(std::ceil(dt / max_step_ - 1e-9));
  const double h = dt / steps;
  for (int s = 0; s < steps; ++s) {
    const double t = time_ + s * h;
    derivative(x_, motor_torque, k1_, t);
    xt_ = x_ + (h / 2) * k1_;
    derivative(xt_, motor_torque, k2_, t + h / 2);
    xt_ = x_ + (h / 2) * k2_;
    derivative(xt_, motor_torque, k3_, t + h / 2);
    xt_ = x_ + h * k3_;
    derivative(xt_, motor_torque, k4_, t + h);
    x_ += (h / 6) * (k1_ + 2 * k2_ + 2 * k3_ + k4_);
  }
  time_ += dt;
}

double Plant::extra_friction(int j, double v) const {
  if (!friction_) return 0;
  const double level = fc_(j) + fs_(j) * std::exp(-(v / v_s_) * (v / v_s_));
  return level * std::tanh(v / v_eps_);
}

void Plant::derivative(const Eigen::VectorXd& x, const Eigen::VectorXd& motor_torque, Eigen::VectorXd& dx,
                       double t) const {
  const int n = n_;
  const double* q = x.data();
  const double* qd = x.data() + n;
  dx.setZero();
  for (int j = 0; j < n; ++j) {
    const double drive = motor_torque(j) + offset_(j);
    if (half_width_(j) > 0) {
      const double qm = x(2 * n + j), qdm = x(3 * n + j);
      const double delta = qm - q[j], hw = half_width_(j);
      // A dead zone with rounded corners (radius eps = hw / 20): a kink would cost RK4 its
      // order at every contact; the smooth one keeps it while the play stays the same.
      const double eps = hw / 20, up = delta - hw, down = delta + hw;
      const double ru = std::sqrt(up * up + eps * eps), rd = std::sqrt(down * down + eps * eps);
      const double deflection = 0.5 * (up + ru) + 0.5 * (down - rd);
      const double contact = 0.5 * (1 + up / ru) + 0.5 * (1 - down / rd);  // d deflection / d delta, in [0, 1]
      const double mesh = stiffness_(j) * deflection + mesh_damping_(j) * contact * (qdm - qd[j]);
      tau_(j) = mesh;
      dx(2 * n + j) = qdm;
      dx(3 * n + j) = (drive - fv_(j) * qdm - extra_friction(j, qdm) - mesh) / ia_(j);
    } else {
      tau_(j) = drive - extra_friction(j, qd[j]);
    }
  }
  if (effects_.contact) tau_(effects_.contact_joint - 1) += effects_.contact_at(t);  // on the link
  model_.forward_dynamics(q, qd, tau_.data(), (backlash_ ? phi_links_ : phi_).data(), dx.data() + n);
  dx.head(n) = x.segment(n, n);
}

double Plant::kinetic_energy() const {
  Eigen::MatrixXd M(n_, n_);
  model_.inertia(x_.data(), phi_.data(), M.data());
  return 0.5 * qd().dot(M * qd());
}

}  // namespace symoro::twin
