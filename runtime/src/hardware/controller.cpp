// The control loop's public pieces: stop reasons, timing summary, the stop signals, the safe
// stop (torque off) and run_control (the loop itself: control_loop.cpp, stop_hold.cpp).
#include "symoro/hardware/controller.hpp"

#include "control_loop.hpp"

#include <time.h>

#include <algorithm>
#include <cerrno>

#include <fmt/format.h>

namespace symoro::hardware {

namespace xs = dynamixel::xseries;
using Clock = std::chrono::steady_clock;
using dynamixel::Bus;
using dynamixel::Outcome;
using dynamixel::Reply;

const char* to_string(StopReason reason) {
  switch (reason) {
    case StopReason::completed: return "completed";
    case StopReason::signal: return "signal";
    case StopReason::watchdog: return "watchdog";
    case StopReason::servo_lost: return "servo_lost";
    case StopReason::hardware_error: return "hardware_error";
    case StopReason::position_limit: return "position_limit";
    case StopReason::velocity_limit: return "velocity_limit";
    case StopReason::current_limit: return "current_limit";
    case StopReason::invalid_command: return "invalid_command";
    case StopReason::setup_failed: return "setup_failed";
    case StopReason::error: return "error";
  }
  return "?";
}

std::string TimingStats::summary() const {
  return fmt::format(
      "{} cycles, period mean {:.1f} us (std {:.1f}, min {:.1f}, max {:.1f}), max jitter {:.1f} us\n"
      "wake-up latency mean {:.1f} us, max {:.1f} us; work mean {:.1f} us, max {:.1f} us; longest sync read {:.1f} us\n"
      "{} overruns, {} deadlines skipped, {} failed sync reads (longest run {}), {} failed sync writes, {} saturated cycles\n"
      "bus: {} transactions, {} retries, {} timeouts, {} CRC errors, {} corrupt, {} alerts",
      cycles, period_mean * 1e6, period_std * 1e6, period_min * 1e6, period_max * 1e6, jitter_max * 1e6, latency_mean * 1e6,
      latency_max * 1e6, work_mean * 1e6, work_max * 1e6, read_max * 1e6, overruns, skipped, read_failures, max_stale,
      write_failures, saturated, bus.transactions, bus.retries, bus.timeouts, bus.crc_errors, bus.corrupt, bus.alerts);
}

// ---- Signals --------------------------------------------------------------------------------------

namespace {
// Lock-free, so the handler may touch it (a signal handler may only use lock-free atomics).
std::atomic<int> g_stop{0};
static_assert(std::atomic<int>::is_always_lock_free, "the stop flag must be lock-free for the signal handler");
extern "C" void stop_signal_handler(int) { g_stop.fetch_add(1, std::memory_order_relaxed); }
}  // namespace

std::atomic<int>& stop_flag() { return g_stop; }

StopSignals::StopSignals() : previous_(new struct sigaction[2]) {
  g_stop.store(0);
  struct sigaction sa {};
  sa.sa_handler = stop_signal_handler;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: a sleeping loop wakes up at once
  sigaction(SIGINT, &sa, &previous_[0]);
  sigaction(SIGTERM, &sa, &previous_[1]);
}

StopSignals::~StopSignals() {
  sigaction(SIGINT, &previous_[0], nullptr);
  sigaction(SIGTERM, &previous_[1], nullptr);
  delete[] previous_;
  g_stop.store(0);  // served its run: a later run without handlers must not stop at once
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

void sleep_until(Clock::time_point t, const std::atomic<int>& stop, int seen) {
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
  timespec ts{static_cast<time_t>(ns / 1'000'000'000), static_cast<long>(ns % 1'000'000'000)};
  // libstdc++'s steady_clock is CLOCK_MONOTONIC.
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR)
    if (stop.load(std::memory_order_relaxed) > seen) return;
}
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
  const auto replies = bus.sync_read(ids, xs::kTorqueEnable.address, xs::kTorqueEnable.size, Clock::now() + std::chrono::milliseconds(200));
  for (const Reply& r : replies) all = all && r.has_data() && r.get<std::uint8_t>(0) == 0;
  return all;
}

ControlResult run_control(Bus& bus, const HardwareConfig& hw, const std::vector<JointInfo>& joints, const control::FfpdGains& gains,
                          const trajectory::Trajectory& traj, const std::string& csv, const ControlOptions& options) {
  detail::Loop loop(bus, hw, joints, gains, traj, options);
  return loop.run(csv);
}

}  // namespace symoro::hardware
