#include "symoro/twin_bus/twin_servo_backend.hpp"

namespace symoro::twin_bus {

TwinServoBackend::TwinServoBackend(const robot::ModelHandle& full, const twin::TwinConfig& config,
                                   const hardware::HardwareConfig& hw, const Eigen::VectorXd& q0)
    : truth_(twin::make_truth(full, config)), plant_(full, truth_, config, q0) {
  const int n = full.nq();
  if (static_cast<int>(hw.joints.size()) != n || static_cast<int>(config.servos.size()) != n)
    throw std::invalid_argument("TwinServoBackend: hardware.yaml and twin.yaml need one servo per joint");
  kt_.resize(n), dir_.resize(n), offset_.resize(n);
  for (int j = 0; j < n; ++j) {
    const double scale = config.effects.torque_constant_error ? config.effects.torque_constant_scale(j) : 1.0;
    kt_(j) = config.servos[j].torque_constant * scale;
    dir_(j) = hw.joints[j].direction;
    offset_(j) = (hw.joints[j].zero - dynamixel::xseries::kCenterPosition) * dynamixel::xseries::kPositionUnit;
  }
  current_ = torque_ = Eigen::VectorXd::Zero(n);
}

void TwinServoBackend::advance(double time) {
  if (!started_) {
    started_ = true;
    time_ = time;
    return;
  }
  const double dt = time - time_;
  if (!(dt > 0)) return;
  time_ = time;
  // Servo currents -> joint torques (direction), held over dt.
  torque_ = kt_.cwiseProduct(dir_).cwiseProduct(current_);
  plant_.advance(dt, torque_);
  ++steps_;
}

dynamixel::JointState TwinServoBackend::state(std::size_t index) const {
  const int j = static_cast<int>(index);
  // Servo angle such that the controller's (pulses - zero) * direction gives q.
  return {dir_(j) * plant_.q()(j) + offset_(j), dir_(j) * plant_.qd()(j), current_(j)};
}

}  // namespace symoro::twin_bus
