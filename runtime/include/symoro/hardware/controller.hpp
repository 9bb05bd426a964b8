// The arm's 1 kHz control loop over a DYNAMIXEL bus (paper Sec. III): every period, paced by
// absolute deadlines (clock_nanosleep TIMER_ABSTIME on CLOCK_MONOTONIC, the steady clock; a
// test may give the loop a clock it steps, loop_clock.hpp),
//   1. Sync Read Present Current, Velocity and Position (one 10-byte read, all servos),
//   2. convert to joint units (hardware.yaml: zero, direction, torque constant),
//   3. check the safety limits, compute the paper's FF+PD with pseudo differentiation
//      (control/ffpd.hpp) plus an optional model feedforward (e.g. the generated inverse
//      dynamics with identified parameters: model_feedforward<Model>(phi)),
//   4. Sync Write Goal Current (saturated at the joints' current limits),
//   5. stream one log row (io::LogStream: the project's log format, flushed every 100 ms).
// Phases: start (ping and check every servo's model, torque off, current mode, Return Delay
// Time, torque on), approach (a smooth move from the measured pose to the trajectory's start at
// safety.approach_speed), pre-roll (hold, safety.pre_roll), trajectory (logged, t = 0 at its
// start), then the end of the trajectory or of `seconds`.
//
// Safe stop, whatever ends the run (completion, a stop signal through the stop flag, watchdog:
// watchdog_cycles consecutive failed sync reads, a servo's hardware alert, a servo that stops
// answering, a joint beyond its position, velocity or current limit, a non-finite command, an
// exception): first what hardware.yaml's safety.at_stop says (hold the stop pose with the run's
// gains for hold_time, or nothing; never after a stop that leaves no state or no obedient
// servo), then Goal Current 0 to every servo, Torque Enable 0 broadcast (both repeated) and read
// back, the log closed with the reason, the action at stop and timing statistics in its sidecar
// notes, the reason returned. The loop never waits on a lock: the log rows go to the writer
// thread through a lock-free queue (io::LogStream). docs/safety.md says all of it in one page.
#pragma once

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/control/ffpd.hpp"
#include "symoro/dynamixel/bus.hpp"
#include "symoro/hardware/config.hpp"
#include "symoro/hardware/loop_clock.hpp"
#include "symoro/model_info.hpp"
#include "symoro/robot/model_handle.hpp"
#include "symoro/trajectory/trajectory.hpp"

namespace symoro::hardware {

enum class StopReason {
  completed,       // the trajectory (or the requested seconds) ran to its end
  signal,          // the stop flag was raised (a stop signal: stop_signals())
  watchdog,        // watchdog_cycles consecutive sync reads failed (state too old)
  servo_lost,      // a servo stopped answering (named in the message)
  bus_watchdog,    // the loop was away past safety.bus_watchdog: a servo stopped itself
  hardware_error,  // a servo's alert bit: Hardware Error Status named in the message
  position_limit,
  velocity_limit,
  current_limit,
  invalid_command,  // a torque or current command not finite (NaN, inf): named, never zeroed
  setup_failed,     // a servo missing, of the wrong model, or refusing the configuration
  error,            // an exception (serial port failure, log write failure)
};
const char* to_string(StopReason reason);

// Per-cycle timing, in seconds unless named otherwise.
struct TimingStats {
  std::int64_t cycles = 0;    // control cycles run (all phases)
  std::int64_t overruns = 0;  // cycles whose work ended after the next deadline
  std::int64_t skipped = 0;   // deadlines skipped after an overrun
  double period_mean = 0, period_std = 0, period_min = 0, period_max = 0;  // between wake-ups
  double jitter_max = 0;                                                   // max |period - T|
  double latency_mean = 0, latency_max = 0;                                // wake-up after the deadline
  double work_mean = 0, work_max = 0;                                      // wake-up to the end of the cycle's work
  double read_max = 0;                                                     // the longest sync read
  std::int64_t read_failures = 0;   // cycles whose sync read lacked a servo's data
  std::int64_t write_failures = 0;  // sync writes not sent in time
  std::int64_t max_stale = 0;       // most consecutive failed reads
  std::int64_t saturated = 0;       // cycles with a command at its current limit
  dynamixel::BusStats bus;
  std::string summary() const;  // several lines, for people and the log's notes
};

struct ControlOptions {
  double seconds = 0;  // run only this much of the trajectory (0: all of it)
  // Stop requests, counted (a signal handler may touch a lock-free atomic): one more than at
  // the start stops the run, a further one ends the hold at once. nullptr: the process's
  // stop signals count (stop_flag()).
  const std::atomic<int>* stop = nullptr;
  // Extra joint torque added to FF+PD (N m), from the references: e.g. model_feedforward.
  // When set, the FF+PD's own realization feedforward (M-hat qdd_ref + D-hat qd_ref) is
  // replaced by it (the PD part remains).
  std::function<void(const Eigen::VectorXd& q_ref, const Eigen::VectorXd& qd_ref, const Eigen::VectorXd& qdd_ref,
                     Eigen::VectorXd& tau)>
      feedforward;
  // The model behind `feedforward`: its mass matrix M(q) (nq x nq; model_inertia<Model>(phi)).
  // A feedforward is checked before torque is enabled (else the run stops as setup_failed, torque
  // never on): at every reference the loop will command (the approach from the measured pose,
  // the pre-roll, the trajectory; every period) and at the measured start pose, the feedforward
  // is finite and within each joint's torque limit, and M is positive definite (when given). A
  // file's `accepted: true` is no evidence: an edited parameter would drive the arm. Only a
  // feedforward that passed may add its gravity to the hold at a stop, and only at a stop it
  // cannot have caused (a signal, the end, an exception).
  std::function<void(const Eigen::VectorXd& q, Eigen::MatrixXd& M)> inertia;
  // Consecutive failed sync reads that stop the run (0: hardware.yaml's safety.watchdog_cycles).
  // An emulated bus on a loaded machine needs more than a real one: its servos are a thread
  // that may wait milliseconds for a core.
  int watchdog_cycles = 0;
  int realtime_priority = 0;  // SCHED_FIFO priority for the loop (0: leave; failure is a warning)
  bool verbose = true;        // progress and the summary on stderr
  // Log: robot name, trajectory and notes go in the sidecar; the rest is filled in.
  std::string robot, source = "robot", notes;
  int trial = 1;
  std::chrono::milliseconds log_flush{100};
  // When set, the loop stores its trajectory time (s; negative during the approach and the
  // pre-roll) here every cycle, so another thread can act on the controller's own timeline
  // (tests inject faults this way, never at a wall-clock time).
  std::atomic<double>* timeline = nullptr;
  // The time the loop and the hold run on (loop_clock.hpp); nullptr: the steady clock, as the
  // arm needs. A test gives a SteppedClock, so that a loaded machine cannot make the loop late.
  LoopClock* clock = nullptr;
};

struct ControlResult {
  StopReason reason = StopReason::error;
  std::string message;  // one line: what stopped the run and where
  TimingStats timing;
  std::int64_t rows = 0;              // log rows written
  double trajectory_time = 0;         // s of the trajectory run
  Eigen::VectorXd max_error;          // max |q_ref - q| per joint over the logged rows, rad
  bool torque_off_confirmed = false;  // every answering servo read back Torque Enable 0
  // What the arm did between the stop and torque off (hardware.yaml safety.at_stop):
  StopAction stop_action = StopAction::torque_off;  // hold: the stop pose was held first
  double held = 0;                                  // s of hold (less than safety.hold_time when a fault ended it)
  double hold_deviation = 0;                        // max |q - q_stop| over the hold, rad, from the servos' positions
  std::string at_stop;                              // one line: what was done and why (also in the log's notes)
};

// The process-wide count of stop requests, raised by the signal handler of StopSignals.
std::atomic<int>& stop_flag();
// The name of the signal behind the last counted request ("SIGHUP"), "" when none.
std::string last_stop_signal();
// A further stop signal counts as a new request (it ends the hold at a stop) only when it
// arrives this long after the last counted one, or when both are typed at the terminal (Ctrl-C,
// Ctrl-\): `timeout` and systemd send SIGTERM to the process and to its group within
// microseconds, and that pair is one request (docs/safety.md).
inline constexpr double kStopEscalationDelay = 0.5;  // s
// The signals StopSignals turns into stop requests: every catchable one whose default action
// ends the process (SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR1, SIGUSR2, SIGALRM, ..., the
// real-time signals), but SIGPIPE, which it ignores, and the faults no program continues after.
const std::vector<int>& stop_signals();
// While it lives: handlers for stop_signals() that only count in stop_flag() (cleared first),
// and SIGPIPE ignored; the previous dispositions are restored when it is destroyed.
class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

 private:
  std::vector<int> signals_;
  std::vector<struct sigaction> previous_;
  struct sigaction pipe_previous_ {};
};

// Runs `traj` on the arm behind `bus` with FF+PD `gains` (period = hw.period), logging to `csv`.
// `joints`: the robot's joints (names, limits); hw.joints are in the same order.
ControlResult run_control(dynamixel::Bus& bus, const HardwareConfig& hw, const std::vector<JointInfo>& joints,
                          const control::FfpdGains& gains, const trajectory::Trajectory& traj, const std::string& csv,
                          const ControlOptions& options);

// Goal Current 0 and Torque Enable 0 on every servo of `hw` (sync write, then broadcast, each
// twice), then reads Torque Enable back; true when every servo answered 0.
bool safe_stop(dynamixel::Bus& bus, const HardwareConfig& hw);

// The identified model's inverse dynamics as a feedforward: tau = ID(q_ref, qd_ref, qdd_ref; phi),
// and its mass matrix, for ControlOptions::inertia: any robot's model through its handle (one
// indirect call each; no allocation once tau and M are sized). std::invalid_argument when phi is
// not the model's size.
std::function<void(const Eigen::VectorXd&, const Eigen::VectorXd&, const Eigen::VectorXd&, Eigen::VectorXd&)>
model_feedforward(const robot::ModelHandle& model, const Eigen::VectorXd& phi);
std::function<void(const Eigen::VectorXd&, Eigen::MatrixXd&)> model_inertia(const robot::ModelHandle& model,
                                                                            const Eigen::VectorXd& phi);

// The same for a generated Model linked statically (a real-time application).
template <class Model>
auto model_feedforward(const Eigen::VectorXd& phi) {
  using Vec = Eigen::Matrix<double, Model::nq, 1>;
  using Phi = Eigen::Matrix<double, Model::np, 1>;
  const Phi p = phi;
  return [p](const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd, Eigen::VectorXd& tau) {
    Vec out;
    Model::inverse_dynamics(Vec(q), Vec(qd), Vec(qdd), p, out);
    tau = out;
  };
}

template <class Model>
auto model_inertia(const Eigen::VectorXd& phi) {
  using Vec = Eigen::Matrix<double, Model::nq, 1>;
  using Phi = Eigen::Matrix<double, Model::np, 1>;
  using Mat = Eigen::Matrix<double, Model::nq, Model::nq>;
  const Phi p = phi;
  return [p](const Eigen::VectorXd& q, Eigen::MatrixXd& M) {
    Mat out;
    Model::inertia(Vec(q), p, out);
    M = out;
  };
}

}  // namespace symoro::hardware
