// The digital twin's arm behind the virtual DYNAMIXEL bus: the servos' currents drive the twin's
// plant (twin/plant.hpp, the robot's full model plus the twin's mechanical effects), so the real
// driver (SerialPort, Bus, the control loop) talks to a simulated arm over a real byte stream.
//
//   auto backend = std::make_unique<TwinServoBackend>(full_model, twin_config, hw, q0);
//   auto* twin = backend.get();   // inspect after the bus is idle
//   dynamixel::VirtualBus bus(servos_from(hw), std::move(backend));
//
// Torque = current x torque constant as the twin models it (twin.yaml servos, times the
// torque_constant_error scale when that effect is on), with the joint direction of hardware.yaml;
// the servo's angle is the joint angle mapped through hardware.yaml's zero and direction, so the
// controller's conversions are exercised. Between bus instructions the currents are held
// (sample and hold); the plant integrates to each instruction's arrival time (the virtual bus's
// wall clock), so a late controller really lets the arm drift. Not modelled here: the twin's
// sensor noise, actuation delay and timestamp effects (the bus and the OS supply the timing).
// Called from the virtual bus's thread; read q()/qd() only while the bus is idle.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/dynamixel/control_table.hpp"
#include "symoro/dynamixel/servo_backend.hpp"
#include "symoro/dynamixel/virtual_bus.hpp"
#include "symoro/hardware/config.hpp"
#include "symoro/robot/model_handle.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/plant.hpp"
#include "symoro/twin/truth.hpp"

namespace symoro::twin_bus {

// The virtual servos of a hardware description (IDs, models), in joint order, with Return Delay
// Time as configured and Operating Mode left at the factory value (the controller sets it).
inline std::vector<dynamixel::VirtualServo> virtual_servos(const hardware::HardwareConfig& hw) {
  std::vector<dynamixel::VirtualServo> out;
  for (const hardware::JointHardware& j : hw.joints) {
    dynamixel::VirtualServo s;
    s.id = j.id;
    const dynamixel::xseries::Model* m = dynamixel::xseries::find_model(j.model.model_number);
    if (!m)
      throw std::invalid_argument("virtual_servos: model number " + std::to_string(j.model.model_number) +
                                  " is not emulated");
    s.model = *m;
    s.return_delay = static_cast<std::uint8_t>(hw.return_delay_time);
    out.push_back(s);
  }
  return out;
}

class TwinServoBackend : public dynamixel::ServoBackend {
 public:
  // full: the robot's full model (the twin's plant); q0: the arm's initial joint angles (at rest).
  TwinServoBackend(const robot::ModelHandle& full, const twin::TwinConfig& config, const hardware::HardwareConfig& hw,
                   const Eigen::VectorXd& q0);

  std::size_t size() const override { return static_cast<std::size_t>(plant_.joints()); }
  void advance(double time) override;
  void set_current(std::size_t index, double amps) override { current_(static_cast<int>(index)) = amps; }
  dynamixel::JointState state(std::size_t index) const override;

  // The twin's true joint state (rad, rad/s), and the time it has been integrated to.
  Eigen::VectorXd q() const { return plant_.q(); }
  Eigen::VectorXd qd() const { return plant_.qd(); }
  double time() const { return time_; }
  std::uint64_t steps() const { return steps_; }
  const twin::Truth& truth() const { return truth_; }

 private:
  twin::Truth truth_;
  twin::Plant plant_;
  Eigen::VectorXd kt_, dir_, offset_, current_, torque_;
  double time_ = 0;
  bool started_ = false;
  std::uint64_t steps_ = 0;
};

}  // namespace symoro::twin_bus
