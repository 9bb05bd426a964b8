// The control loop's public pieces: stop reasons, timing summary, the stop signals, the safe
// stop (torque off) and run_control (the loop itself: control_loop.cpp, stop_hold.cpp).
#include "symoro/hardware/controller.hpp"

#include "control_loop.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>

#include <fmt/format.h>

namespace symoro::hardware {

namespace xs = dynamixel::xseries;
using Clock = std::chrono::steady_clock;
using dynamixel::Bus;
using dynamixel::Outcome;
using dynamixel::Reply;

const char* to_string(StopReason reason) {
  switch (reason) {
    case StopReason::completed:
      return "completed";
    case StopReason::signal:
      return "signal";
    case StopReason::watchdog:
      return "watchdog";
    case StopReason::servo_lost:
      return "servo_lost";
    case StopReason::bus_watchdog:
      return "bus_watchdog";
    case StopReason::hardware_error:
      return "hardware_error";
    case StopReason::position_limit:
      return "position_limit";
    case StopReason::velocity_limit:
      return "velocity_limit";
    case StopReason::current_limit:
      return "current_limit";
    case StopReason::invalid_command:
      return "invalid_command";
    case StopReason::setup_failed:
      return "setup_failed";
    case StopReason::error:
      return "error";
  }
  return "?";
}

std::string TimingStats::summary() const {
  return fmt::format(
      "{} cycles, period mean {:.1f} us (std {:.1f}, min {:.1f}, max {:.1f}), max jitter {:.1f} us\n"
      "wake-up latency mean {:.1f} us, max {:.1f} us; work mean {:.1f} us, max {:.1f} us; longest sync read {:.1f} us\n"
      "{} overruns, {} deadlines skipped, {} failed sync reads (longest run {}), {} failed sync writes, {} saturated "
      "cycles\n"
      "bus: {} transactions, {} retries, {} timeouts, {} CRC errors, {} corrupt, {} alerts",
      cycles, period_mean * 1e6, period_std * 1e6, period_min * 1e6, period_max * 1e6, jitter_max * 1e6,
      latency_mean * 1e6, latency_max * 1e6, work_mean * 1e6, work_max * 1e6, read_max * 1e6, overruns, skipped,
      read_failures, max_stale, write_failures, saturated, bus.transactions, bus.retries, bus.timeouts, bus.crc_errors,
      bus.corrupt, bus.alerts);
}

// ---- Safe stop --------------------------------------------------------------------------------

namespace detail {
PatientBus::PatientBus(Bus& bus) : bus_(bus), saved_(bus.options()) {
  dynamixel::BusOptions o = saved_;
  o.margin = std::max<std::chrono::microseconds>(o.margin, std::chrono::milliseconds(20));
  o.retries = std::max(o.retries, 3);
  bus_.set_options(o);
}
PatientBus::~PatientBus() { bus_.set_options(saved_); }

}  // namespace detail

bool safe_stop(Bus& bus, const HardwareConfig& hw) {
  detail::PatientBus patient(bus);
  const std::vector<std::uint8_t> ids = hw.ids();
  const std::vector<std::int32_t> zeros(ids.size(), 0);
  const auto soon = [] { return Clock::now() + std::chrono::milliseconds(5); };
  for (int pass = 0; pass < 2; ++pass) {
    bus.sync_write(ids, xs::kGoalCurrent, zeros, soon());
    bus.write(dynamixel::kBroadcastId, xs::kTorqueEnable, 0, soon());
    bus.sync_write(ids, xs::kTorqueEnable, zeros, soon());
  }
  bool all = true;
  const auto replies = bus.sync_read(ids, xs::kTorqueEnable.address, xs::kTorqueEnable.size,
                                     Clock::now() + std::chrono::milliseconds(200));
  for (const Reply& r : replies) all = all && r.has_data() && r.get<std::uint8_t>(0) == 0;
  return all;
}

ControlResult run_control(Bus& bus, const HardwareConfig& hw, const std::vector<JointInfo>& joints,
                          const control::FfpdGains& gains, const trajectory::Trajectory& traj, const std::string& csv,
                          const ControlOptions& options) {
  detail::Loop loop(bus, hw, joints, gains, traj, options);
  return loop.run(csv);
}

}  // namespace symoro::hardware
