// What the arm does between a stop and torque off (hardware.yaml safety.at_stop): a
// gravity-loaded arm falls when its torque goes off, so by default the stop pose is held with the
// run's own controller (its gains and its velocity filter's state, plus the model feedforward's
// gravity when there is one and it is finite) for safety.hold_time. A stop that leaves nothing
// trustworthy to hold with turns torque off at once, and any new fault ends the hold.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "control_loop.hpp"

namespace symoro::hardware::detail {

namespace xs = dynamixel::xseries;

void Loop::at_stop(const StopNow& stop, ControlResult& result) {
  result.stop_action = StopAction::torque_off;
  if (!torque_on_) {
    result.at_stop = "torque off (it had not been turned on)";
    return;
  }
  switch (stop.reason) {
    case StopReason::watchdog:
    case StopReason::servo_lost:
      result.at_stop = "torque off at once: the servos' state is lost, no pose to hold";
      return;
    case StopReason::bus_watchdog:
      result.at_stop = "torque off at once: the servos stopped themselves (their bus watchdog), nothing to hold with";
      return;
    case StopReason::hardware_error:
      result.at_stop = "torque off at once: a servo reports a hardware error";
      return;
    case StopReason::current_limit:
      result.at_stop = "torque off at once: a servo draws more current than it is commanded";
      return;
    case StopReason::setup_failed:
      result.at_stop = "torque off at once: the setup failed";
      return;
    default:
      break;
  }
  if (hw_.safety.at_stop == StopAction::torque_off) {
    result.at_stop = "torque off at once (safety.at_stop: torque_off)";
    return;
  }
  if (!ctrl_) {
    result.at_stop = "torque off at once: the loop had not started";
    return;
  }
  // Gravity at the stop pose from the model feedforward: only from a model that passed its checks
  // before torque on, and only at a stop it cannot have caused. A limit stop may be the
  // feedforward's doing (a wrong model drives the arm away), and its gravity would hold the arm
  // with the same error: PD alone then.
  Eigen::VectorXd gravity = Eigen::VectorXd::Zero(n_);
  std::string with = "PD";
  const bool innocent =
      stop.reason == StopReason::signal || stop.reason == StopReason::completed || stop.reason == StopReason::error;
  if (o_.feedforward && !feedforward_checked_) {
    with = "PD (the model feedforward was not checked)";
  } else if (o_.feedforward && stop.reason == StopReason::invalid_command) {
    with = "PD";  // the feedforward is what failed
  } else if (o_.feedforward && !innocent) {
    with = fmt::format("PD (a {} stop may come from the model feedforward)", to_string(stop.reason));
  } else if (o_.feedforward) {
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n_);
    Eigen::VectorXd g(n_);
    o_.feedforward(q_, zero, zero, g);
    bool within = g.size() == n_ && g.allFinite();
    for (int j = 0; within && j < n_; ++j) within = std::abs(g(j)) <= limit_(j) * kt_(j);
    if (within) {
      gravity = g;
      with = "PD + the model's gravity";
    } else {
      with = "PD (the model's gravity is not finite or beyond a joint's torque limit)";
    }
  }
  result.stop_action = StopAction::hold;
  const std::string ended = hold(gravity, result);
  result.at_stop =
      fmt::format("hold {:.3f} s at the stop pose ({}; max deviation {:.3f} deg){}, then torque off", result.held, with,
                  result.hold_deviation * 180 / 3.14159265358979323846, ended.empty() ? "" : ", ended early: " + ended);
}

// Holds q at the stop for safety.hold_time; returns why it ended early ("" when it did not).
std::string Loop::hold(const Eigen::VectorXd& gravity, ControlResult& result) {
  const Eigen::VectorXd q_hold = q_;
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n_);
  const auto T = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(T_));
  const std::int64_t cycles = std::max<std::int64_t>(1, std::llround(hw_.safety.hold_time / T_));
  const int seen = stop_->load();  // a request from now on ends the hold
  const auto start = clock_.now() + T;
  int stale = 0;
  Clock::time_point previous_wake{};
  for (std::int64_t k = 0; k < cycles; ++k) {
    const auto deadline = start + k * T;
    clock_.sleep_until(deadline, *stop_, seen);
    result.held = k * T_;
    if (stop_->load() > seen) return "a further stop request";
    const auto wake = clock_.now();
    bool fresh = false;
    try {
      if (previous_wake != Clock::time_point{}) check_bus_watchdog(wake - previous_wake);
      previous_wake = wake;
      fresh = read_state(clock_.io_deadline(std::max(deadline + T * 8 / 10, wake + T / 2)),
                         /*setup=*/true);  // counts no watchdog of the run
      if (fresh) check_current();
    } catch (const StopNow& fault) {
      return fault.message;
    }
    stale = fresh ? 0 : stale + 1;
    if (stale >= watchdog_) return fmt::format("{} consecutive failed sync reads", stale);
    if (fresh) result.hold_deviation = std::max(result.hold_deviation, (q_ - q_hold).cwiseAbs().maxCoeff());
    tau_ = ctrl_->update(q_, q_hold, zero, zero) + gravity;
    for (int j = 0; j < n_; ++j) {
      const double raw = std::round(hw_.joints[j].direction * tau_(j) / kt_(j) / unit_(j));
      if (!std::isfinite(raw))
        return fmt::format("joint {} {}: the hold's command is {}", j + 1, joints_[j].name, tau_(j));
      const double bound = limit_raw_[j];
      command_[j] = static_cast<std::int32_t>(std::clamp(raw, -bound, bound));
    }
    bus_.sync_write(ids_, xs::kGoalCurrent, dynamixel::Span<const std::int32_t>(command_.data(), command_.size()),
                    clock_.io_deadline(std::max(deadline + T * 95 / 100, clock_.now() + T / 4)));
  }
  result.held = cycles * T_;
  return "";
}

}  // namespace symoro::hardware::detail
