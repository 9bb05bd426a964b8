// The physics behind emulated servos (virtual_bus.hpp): what a current command does to the
// joints. The virtual bus owns the protocol and the control tables; a backend only integrates
// motion, so a digital twin of the whole arm (symoro/twin/) can replace the simple one below.
//
// Called from the virtual bus's thread only, in this order per instruction: advance(t) to the
// instruction's arrival time, then set_current() for servos whose command changed, or state()
// to fill Present Current/Velocity/Position.
#pragma once

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace symoro::dynamixel {

struct JointState {
  double position = 0;  // rad, 0 at the servo's center pulse (2048)
  double velocity = 0;  // rad/s
  double current = 0;   // A, what the motor draws
};

class ServoBackend {
 public:
  virtual ~ServoBackend() = default;
  virtual std::size_t size() const = 0;
  // Integrates to `time` (s on the virtual bus's clock), holding the currents set so far.
  virtual void advance(double time) = 0;
  // The current servo `index` drives from now on (A); 0 when its torque is off.
  virtual void set_current(std::size_t index, double amps) = 0;
  virtual JointState state(std::size_t index) const = 0;
};

// Each joint a rotor on its own: J qdd = kt i - b qd, integrated exactly for piecewise-constant
// current (exponential solution between commands), so a test can compare with the closed form.
class RotorBackend : public ServoBackend {
 public:
  struct Rotor {
    double inertia = 0.01;            // J, kg m^2 (> 0)
    double damping = 0.02;            // b, N m s/rad (>= 0)
    double torque_constant = 2.3179;  // kt, N m/A (XM430-W350; XM540-W270: 3.1317)
    double position = 0;              // initial q, rad
  };

  explicit RotorBackend(std::vector<Rotor> rotors) : rotors_(std::move(rotors)) {
    for (std::size_t i = 0; i < rotors_.size(); ++i) {
      if (!(rotors_[i].inertia > 0) || !(rotors_[i].damping >= 0))
        throw std::invalid_argument("RotorBackend: rotor " + std::to_string(i) + " needs inertia > 0 and damping >= 0");
      states_.push_back(JointState{rotors_[i].position, 0, 0});
    }
  }

  std::size_t size() const override { return rotors_.size(); }

  void advance(double time) override {
    if (!started_) {
      started_ = true;
      time_ = time;
      return;
    }
    const double h = time - time_;
    if (!(h > 0)) return;
    time_ = time;
    for (std::size_t i = 0; i < rotors_.size(); ++i) {
      const Rotor& r = rotors_[i];
      JointState& s = states_[i];
      const double torque = r.torque_constant * s.current;
      if (r.damping == 0) {  // pure inertia
        const double a = torque / r.inertia;
        s.position += s.velocity * h + 0.5 * a * h * h;
        s.velocity += a * h;
        continue;
      }
      const double tau = r.inertia / r.damping;    // time constant
      const double w_end = torque / r.damping;     // steady velocity
      const double decay = -std::expm1(-h / tau);  // 1 - exp(-h/tau), exact for small h too
      s.position += w_end * h + (s.velocity - w_end) * tau * decay;
      s.velocity += (w_end - s.velocity) * decay;
    }
  }

  void set_current(std::size_t index, double amps) override { states_.at(index).current = amps; }
  JointState state(std::size_t index) const override { return states_.at(index); }
  const Rotor& rotor(std::size_t index) const { return rotors_.at(index); }

 private:
  std::vector<Rotor> rotors_;
  std::vector<JointState> states_;
  double time_ = 0;
  bool started_ = false;  // the first advance() sets the clock without moving
};

}  // namespace symoro::dynamixel
