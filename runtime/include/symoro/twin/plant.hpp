// The simulated arm: the robot's full model (forward dynamics: products of inertia, rotor
// inertia, viscous friction) plus the twin's switchable physical effects, integrated with
// classical Runge-Kutta 4 while the motor torques are held constant. Any robot, through its
// ModelHandle (one indirect call of its generated forward dynamics per derivative).
//
// Effects on the mechanics: smooth Coulomb and Stribeck friction, a constant unmeasured torque
// offset, backlash, and a contact (an external torque on one link for a while, at the plant's
// clock: log time). With backlash a joint's rotor becomes its own body: the rotor (rotor
// inertia, viscous and Coulomb friction) drives the link through a dead zone of the given width
// and a stiff, lightly damped gear mesh beyond it; the link side uses the model without that
// joint's rotor inertia and viscous friction.
#pragma once

#include <Eigen/Core>

#include "symoro/robot/model_handle.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/truth.hpp"

namespace symoro::twin {

class Plant {
 public:
  // `model` is the robot's full model (truth from make_truth on it); q0 the start posture, at rest.
  Plant(robot::ModelHandle model, const Truth& truth, const TwinConfig& c, const Eigen::VectorXd& q0);

  int joints() const { return n_; }
  // q, qd (links), then qm, qdm (rotors; used by backlash joints only).
  const Eigen::VectorXd& state() const { return x_; }
  void set_state(const Eigen::VectorXd& x) { x_ = x; }
  auto q() const { return x_.head(n_); }
  auto qd() const { return x_.segment(n_, n_); }
  auto rotor_q() const { return x_.segment(2 * n_, n_); }
  bool has_backlash() const { return backlash_; }
  double max_step() const { return max_step_; }

  // Advances by dt with the motor torques held, in equal RK4 steps no longer than max_step.
  void advance(double dt, const Eigen::VectorXd& motor_torque);
  // The plant's clock (log time; the simulator starts it at the pre-roll's start).
  double time() const { return time_; }
  void set_time(double t) { time_ = t; }

  // The friction beyond viscous: smooth Coulomb plus Stribeck, odd in the velocity.
  double extra_friction(int j, double v) const;

  // dx/dt at x (4 joints-long vectors; dx sized by the caller), the contact's torque at time t.
  void derivative(const Eigen::VectorXd& x, const Eigen::VectorXd& motor_torque, Eigen::VectorXd& dx,
                  double t = 0) const;

  // Mechanical energy of the rigid plant (no backlash): kinetic 1/2 qd' M qd.
  double kinetic_energy() const;

 private:
  robot::ModelHandle model_;
  int n_;
  Eigen::VectorXd phi_, phi_links_;
  double max_step_;
  Eigen::VectorXd fv_, ia_, fc_, fs_, offset_, half_width_, stiffness_, mesh_damping_;
  double v_eps_ = 0.01, v_s_ = 0.05;
  Effects effects_;  // the contact's
  double time_ = 0;
  bool friction_ = false, backlash_ = false;
  Eigen::VectorXd x_;
  Eigen::VectorXd k1_, k2_, k3_, k4_, xt_;  // RK4's stages (no allocation per step)
  mutable Eigen::VectorXd tau_;             // derivative's joint torques
};

}  // namespace symoro::twin
