// The arm's hardware description (robots/<robot>/hardware.yaml): the DYNAMIXEL bus, the servo
// models (torque constant, current unit and limit), and per joint its servo ID, model, the pulse
// count of its zero angle, its direction and its current limit; plus the safety settings of the
// control loop. Read once and checked with file and line, like twin.yaml.
//
//   joint angle  q  = direction * (pulses - zero) * 2 pi / 4096            (rad)
//   joint torque tau = direction * current * torque_constant               (N m)
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "symoro/model_info.hpp"

namespace symoro::hardware {

struct ServoModel {
  std::string name;                // "XM430-W350"
  std::uint16_t model_number = 0;  // Model Number(0), checked by ping at start
  double torque_constant = 0;      // N m / A
  double current_unit = 0;         // A per Goal/Present Current unit
  double current_limit = 0;        // A, the model's maximum
};

struct JointHardware {
  std::string name;     // the model's joint name (checked against the robot's joints)
  std::uint8_t id = 0;  // servo ID
  ServoModel model;
  std::int32_t zero = 2048;  // pulses at q = 0
  int direction = 1;         // +1 or -1
  double current_limit = 0;  // A, commands saturate here (<= the model's limit)
};

// The most consecutive failed reads a real arm may run blind on: 50 cycles, 50 ms at 1 kHz
// (hardware.yaml's watchdog_cycles and dynid control --watchdog on a real port).
inline constexpr int kMaxWatchdogCycles = 50;

// What the loop does at every stop once torque is on (docs/safety.md). A gravity-loaded arm falls
// when its torque goes off, so the default holds: the stop pose with the run's PD gains (and the
// model feedforward's gravity, when it has one and it is finite) for hold_time, then torque off.
// Stops that leave nothing to hold with (watchdog, a lost servo, a hardware error, a current
// trip) turn torque off at once whatever the choice; a new fault during the hold ends it.
enum class StopAction { hold, torque_off };
const char* to_string(StopAction action);

struct Safety {
  int watchdog_cycles = 3;                // consecutive failed sync reads that stop the arm
  double position_tolerance = 0.05;       // rad a joint may pass its robot.yaml limit by
  double velocity_factor = 1.0;           // stop beyond factor * robot.yaml velocity limit
  double current_trip_factor = 1.5;       // stop when |present current| > factor * current_limit
  double approach_speed = 0.3;            // rad/s, the move to the trajectory's start posture
  double pre_roll = 0.5;                  // s holding the start posture before the trajectory
  StopAction at_stop = StopAction::hold;  // safety.at_stop: hold | torque_off
  double hold_time = 2.0;                 // s of hold before torque off (safety.hold_time, > 0)
  // The servos' own Bus Watchdog(98), set before torque on: a servo that hears no instruction
  // packet for this long (the controller crashed, was killed with SIGKILL, or stalled) stops
  // driving its motor by itself. s, rounded up to 20 ms units, 0.02..2.54; 0: off.
  double bus_watchdog = 0.1;
};

struct HardwareConfig {
  std::string path;
  std::uint32_t baud = 3'000'000;
  int return_delay_time = 0;  // Return Delay Time(9) written at start (2 us units)
  double period = 0.001;      // s
  std::vector<JointHardware> joints;
  Safety safety;

  std::vector<std::uint8_t> ids() const;
};

// The range hardware.yaml may set a safety limit to (safety.<key>), so that no value switches
// the limit off: position_tolerance, velocity_factor, current_trip_factor, approach_speed,
// pre_roll, hold_time. std::out_of_range for another key.
struct SafetyBound {
  double lower, upper;
  bool lower_open;  // (lower, upper] rather than [lower, upper]
  const char* unit;
  const char* why;
};
const SafetyBound& safety_bound(const std::string& key);

// Reads hardware.yaml; `robot_joints` (the model's joints) fixes the order and count: the file
// lists one entry per joint, by name. Throws DataError(file, line, ...).
HardwareConfig read_hardware_config(const std::filesystem::path& path, const std::vector<JointInfo>& robot_joints);

}  // namespace symoro::hardware
