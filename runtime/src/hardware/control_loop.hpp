// The control loop's internals (controller.hpp is its public face): one Loop per run_control,
// its phases in control_loop.cpp (setup, approach, pre-roll, trajectory) and stop_hold.cpp (the
// hold at a stop, before torque off).
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/control/ffpd.hpp"
#include "symoro/dynamixel/bus.hpp"
#include "symoro/hardware/config.hpp"
#include "symoro/hardware/controller.hpp"
#include "symoro/hardware/loop_clock.hpp"
#include "symoro/io/log_stream.hpp"

namespace symoro::hardware::detail {

using Clock = std::chrono::steady_clock;

inline double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// Outside the 1 kHz loop (start, stop) transactions may take their time: a servo (or, on the
// virtual bus, the emulating thread) that answers late is waited for and retried.
class PatientBus {
 public:
  explicit PatientBus(dynamixel::Bus& bus);
  ~PatientBus();
  PatientBus(const PatientBus&) = delete;
  PatientBus& operator=(const PatientBus&) = delete;

 private:
  dynamixel::Bus& bus_;
  dynamixel::BusOptions saved_;
};

// Thrown inside the loop: what stops the run.
struct StopNow {
  StopReason reason;
  std::string message;
};

class Loop {
 public:
  Loop(dynamixel::Bus& bus, const HardwareConfig& hw, const std::vector<JointInfo>& joints,
       const control::FfpdGains& gains, const trajectory::Trajectory& traj, const ControlOptions& options);
  ControlResult run(const std::string& csv);

 private:
  std::string joint_name(int j) const;
  void setup();
  bool read_state(Clock::time_point deadline, bool setup = false);  // deadline: on the steady clock
  void check_limits();
  // After a gap of `away` between cycles that may have passed the servos' Bus Watchdog: reads it
  // and stops (watchdog) when a servo tripped.
  void check_bus_watchdog(Clock::duration away);
  void check_current();
  double reference(double s);
  void plan();  // the approach from the measured start pose (q0_) to the trajectory's start
  // feedforward_check.cpp: the model feedforward on every reference the run will command,
  // before torque is enabled (ControlOptions::inertia says what is checked).
  void check_feedforward();
  StopNow loop();
  // One cycle's command: the controller's torque (with the model feedforward) in current units,
  // saturated at each joint's limit; a command that is not a number stops the run.
  void command_torque(control::FfpdController& ctrl, double t);
  // One row of the log (time: since the trajectory's start); a log that cannot be written stops.
  void log_row(const control::FfpdController& ctrl, double time, double t);
  void finish_timing();
  // stop_hold.cpp: what the arm does between the stop and torque off (result.at_stop says).
  void at_stop(const StopNow& stop, ControlResult& result);
  std::string hold(const Eigen::VectorXd& gravity, ControlResult& result);

  dynamixel::Bus& bus_;
  const HardwareConfig& hw_;
  const std::vector<JointInfo>& joints_;
  const control::FfpdGains& gains_;
  const trajectory::Trajectory& traj_;
  const ControlOptions& o_;
  LoopClock& clock_;  // the loop's and the hold's time (o_.clock, else the steady clock)
  int n_;
  std::vector<std::uint8_t> ids_;
  const std::atomic<int>* stop_ = nullptr;
  int stops_seen_ = 0;  // stop requests before the run: a request counts when it comes after
  double T_ = 0.001, approach_ = 0, traj_time_ = 0;
  Eigen::VectorXd q_, qd_servo_, current_, tau_, qr_, qdr_, qddr_, ff_, q0_, qr0_, kt_, limit_, unit_, max_error_;
  std::vector<double> tau_meas_;
  std::vector<std::int32_t> limit_raw_, command_;
  std::vector<int> stale_;
  std::int64_t stale_cycles_ = 0;
  int watchdog_ = 3;
  int bus_watchdog_units_ = 0;  // Bus Watchdog(98) written before torque on (20 ms units; 0: off)
  int alert_id_ = -1;
  bool torque_on_ = false;                       // Torque Enable 1 was written to every servo
  bool feedforward_checked_ = false;             // the model feedforward passed check_feedforward()
  std::int64_t k_end_ = 0;                       // the last cycle of the run (plan())
  std::optional<control::FfpdController> ctrl_;  // the run's controller: the hold continues it
  TimingStats timing_;
  std::array<double, 5> period_stats_{};
  io::LogStream* log_ = nullptr;
};

}  // namespace symoro::hardware::detail
