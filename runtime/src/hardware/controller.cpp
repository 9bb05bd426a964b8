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
// When the last counted request arrived (CLOCK_MONOTONIC, ns; 0: none yet), and whether it was a
// Ctrl-C typed at the terminal.
std::atomic<long long> g_last_ns{0};
std::atomic<bool> g_last_typed{false};
static_assert(std::atomic<long long>::is_always_lock_free && std::atomic<bool>::is_always_lock_free,
              "the signal handler's state must be lock-free");

// One stop request per deliberate act. GNU timeout and systemd send SIGTERM to the process and
// again to its group, microseconds apart: counted twice, that pair would end the hold at once
// and drop the arm. So a further signal counts only when it comes kStopEscalationDelay after the
// last counted one, or when it and that one are both Ctrl-C typed at the terminal (the kernel
// sends those, si_code SI_KERNEL; kill(), timeout and systemd send SI_USER).
extern "C" void stop_signal_handler(int sig, siginfo_t* info, void*) {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);  // async-signal-safe
  const long long now = static_cast<long long>(ts.tv_sec) * 1'000'000'000LL + ts.tv_nsec;
  const bool typed = sig == SIGINT && info != nullptr && info->si_code == SI_KERNEL;
  const long long last = g_last_ns.load(std::memory_order_relaxed);
  const long long delay = std::llround(kStopEscalationDelay * 1e9);
  if (last != 0 && now - last < delay && !(typed && g_last_typed.load(std::memory_order_relaxed))) return;
  g_last_ns.store(now, std::memory_order_relaxed);
  g_last_typed.store(typed, std::memory_order_relaxed);
  g_stop.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

std::atomic<int>& stop_flag() { return g_stop; }

StopSignals::StopSignals() : previous_(new struct sigaction[2]) {
  g_stop.store(0);
  g_last_ns.store(0);
  g_last_typed.store(false);
  struct sigaction sa {};
  sa.sa_sigaction = stop_signal_handler;
  sigemptyset(&sa.sa_mask);
  sigaddset(&sa.sa_mask, SIGINT);  // one handler at a time: the pair's check and update stay whole
  sigaddset(&sa.sa_mask, SIGTERM);
  sa.sa_flags = SA_SIGINFO;  // no SA_RESTART: a sleeping loop wakes up at once
  sigaction(SIGINT, &sa, &previous_[0]);
  sigaction(SIGTERM, &sa, &previous_[1]);
}

StopSignals::~StopSignals() {
  sigaction(SIGINT, &previous_[0], nullptr);
  sigaction(SIGTERM, &previous_[1], nullptr);
  delete[] previous_;
  g_stop.store(0);  // served its run: a later run without handlers must not stop at once
  g_last_ns.store(0);
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
