// The control loop's phases: setup (ping, configure, torque on), approach, pre-roll, trajectory
// (log rows), then what the stop needs (stop_hold.cpp) and torque off (safe_stop).
#include "control_loop.hpp"

#include <pthread.h>
#include <sys/prctl.h>
#include <sched.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <fmt/format.h>

#include "symoro/error.hpp"

namespace symoro::hardware::detail {

namespace xs = dynamixel::xseries;
using dynamixel::Bus;
using dynamixel::Outcome;
using dynamixel::Reply;

namespace {
std::string error_bits(std::uint8_t bits) {
  std::string s;
  const std::pair<std::uint8_t, const char*> names[] = {{xs::hardware_error::kInputVoltage, "input voltage"},
                                                        {xs::hardware_error::kOverheating, "overheating"},
                                                        {xs::hardware_error::kMotorEncoder, "motor encoder"},
                                                        {xs::hardware_error::kElectricalShock, "electrical shock"},
                                                        {xs::hardware_error::kOverload, "overload"}};
  for (const auto& [bit, name] : names)
    if (bits & bit) s += (s.empty() ? "" : ", ") + std::string(name);
  return s.empty() ? "no bit known" : s;
}

// SCHED_FIFO at `priority` (0: leave the policy; refusal is a warning) and a 1 ns timer slack
// (the default 50 us would be added to every wake-up) while it lives: the loop and the hold.
class RealtimeScope {
 public:
  RealtimeScope(int priority, bool verbose) {
    if (priority > 0) {
      pthread_getschedparam(pthread_self(), &old_policy_, &old_param_);
      sched_param p{};
      p.sched_priority = priority;
      on_ = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p) == 0;
      if (!on_ && verbose)
        std::fprintf(stderr, "control: SCHED_FIFO %d refused; running at normal priority\n", priority);
    }
    old_slack_ = prctl(PR_GET_TIMERSLACK, 0, 0, 0, 0);
    prctl(PR_SET_TIMERSLACK, 1, 0, 0, 0);
  }
  ~RealtimeScope() {
    if (on_) pthread_setschedparam(pthread_self(), old_policy_, &old_param_);
    if (old_slack_ > 0) prctl(PR_SET_TIMERSLACK, old_slack_, 0, 0, 0);
  }
  RealtimeScope(const RealtimeScope&) = delete;
  RealtimeScope& operator=(const RealtimeScope&) = delete;

 private:
  bool on_ = false;
  int old_policy_ = 0, old_slack_ = 0;
  sched_param old_param_{};
};

}  // namespace

std::string Loop::joint_name(int j) const {
  return fmt::format("servo ID {} (joint {} {})", int(ids_[j]), j + 1, joints_[j].name);
}

Loop::Loop(Bus& bus, const HardwareConfig& hw, const std::vector<JointInfo>& joints, const control::FfpdGains& gains,
           const trajectory::Trajectory& traj, const ControlOptions& options)
    : bus_(bus),
      hw_(hw),
      joints_(joints),
      gains_(gains),
      traj_(traj),
      o_(options),
      clock_(options.clock ? *options.clock : steady_loop_clock()),
      n_(static_cast<int>(joints.size())),
      ids_(hw.ids()) {
  if (static_cast<int>(hw.joints.size()) != n_)
    throw std::invalid_argument("run_control: hardware.yaml and the robot differ in joints");
  if (traj.joints() != n_)
    throw DataError(traj.name, 0, fmt::format("the trajectory has {} joints, the robot {}", traj.joints(), n_));
  if (gains.inertia.size() != n_) throw std::invalid_argument("run_control: FF+PD gains for another joint count");
  stop_ = options.stop ? options.stop : &stop_flag();
  stops_seen_ = stop_->load();
  watchdog_ = options.watchdog_cycles > 0 ? options.watchdog_cycles : hw.safety.watchdog_cycles;
  T_ = hw.period;
  for (Eigen::VectorXd* v :
       {&q_, &qd_servo_, &current_, &tau_, &qr_, &qdr_, &qddr_, &ff_, &q0_, &qr0_, &kt_, &limit_, &unit_, &max_error_})
    v->setZero(n_);
  for (int j = 0; j < n_; ++j) {
    const JointHardware& h = hw.joints[j];
    kt_(j) = h.model.torque_constant;
    unit_(j) = h.model.current_unit;
    double lim = h.current_limit;
    if (joints[j].effort > 0) lim = std::min(lim, joints[j].effort / kt_(j));
    limit_(j) = lim;
    limit_raw_.push_back(static_cast<std::int32_t>(std::floor(lim / unit_(j))));
  }
  command_.assign(n_, 0);
  stale_.assign(n_, 0);
  if (hw.safety.bus_watchdog > 0)
    bus_watchdog_units_ = static_cast<int>(std::ceil(hw.safety.bus_watchdog / xs::kBusWatchdogUnit - 1e-9));
  tau_meas_.assign(n_, 0.0);
}

ControlResult Loop::run(const std::string& csv) {
  ControlResult result;
  result.max_error = Eigen::VectorXd::Zero(n_);
  io::LogMetadata meta;
  meta.robot = o_.robot;
  meta.trajectory = traj_.name;
  meta.trial = o_.trial;
  meta.source = o_.source;
  meta.sample_time = T_;
  for (const auto& j : joints_) meta.joints.push_back(j.name);
  meta.notes = o_.notes;
  io::LogStream log(csv, meta, true, o_.log_flush);
  log_ = &log;
  StopNow stop{StopReason::error, "not started"};
  const RealtimeScope realtime(o_.realtime_priority, o_.verbose);
  try {
    setup();
    stop = loop();
  } catch (const StopNow& s) {
    stop = s;
  } catch (const std::exception& e) {
    stop = {StopReason::error, e.what()};
  }
  // Hold (safety.at_stop), then the safe stop: whatever happened above.
  finish_timing();
  try {
    at_stop(stop, result);
  } catch (const std::exception& e) {
    result.at_stop += fmt::format("; the hold failed: {}", e.what());
  }
  try {
    result.torque_off_confirmed = safe_stop(bus_, hw_);
  } catch (const std::exception& e) {
    stop.message += fmt::format(" (and the safe stop failed: {})", e.what());
  }
  if (stop.reason == StopReason::hardware_error && alert_id_ >= 0) {
    try {
      PatientBus patient(bus_);
      const Reply r = bus_.read(static_cast<std::uint8_t>(alert_id_), xs::kHardwareErrorStatus,
                                Clock::now() + std::chrono::milliseconds(200));
      if (r.has_data())
        stop.message += fmt::format(": Hardware Error Status 0x{:02x} ({})", r.get<std::uint8_t>(0),
                                    error_bits(r.get<std::uint8_t>(0)));
    } catch (const std::exception&) {
    }
  }
  timing_.bus = bus_.stats();
  result.reason = stop.reason;
  result.message = stop.message;
  result.timing = timing_;
  result.trajectory_time = traj_time_;
  result.max_error = max_error_;
  std::string summary = timing_.summary();
  std::replace(summary.begin(), summary.end(), '\n', ';');
  log.set_notes(fmt::format("{}{}stop: {}: {}; at stop: {}; torque off {}; timing: {}", o_.notes,
                            o_.notes.empty() ? "" : "; ", to_string(stop.reason), stop.message, result.at_stop,
                            result.torque_off_confirmed ? "confirmed" : "NOT confirmed for every servo", summary));
  try {
    log.close();
  } catch (const std::exception& e) {
    // The log ends short (a full disk): its CSV on its last whole row, its sidecar saying so.
    // A run that lost its log is no success, whatever stopped it; the report still follows.
    const std::string lost = fmt::format("{} ({} rows on disk, {} lost)", e.what(), log.written(), log.lost());
    if (result.reason == StopReason::completed) {
      result.reason = StopReason::error;
      result.message = lost;
    } else if (result.message.find(log.error()) == std::string::npos) {
      result.message += "; " + lost;
    }
  }
  result.rows = log.written();
  if (o_.verbose)
    std::fprintf(stderr, "stop: %s: %s\nat stop: %s\ntorque off %s; %lld log rows in %s\n%s\n",
                 to_string(result.reason), result.message.c_str(), result.at_stop.c_str(),
                 result.torque_off_confirmed ? "confirmed" : "NOT confirmed for every servo",
                 static_cast<long long>(result.rows), csv.c_str(), timing_.summary().c_str());
  return result;
}

void Loop::setup() {
  PatientBus patient(bus_);
  const auto wait = [] { return Clock::now() + std::chrono::milliseconds(200); };
  for (int j = 0; j < n_; ++j) {
    const JointHardware& h = hw_.joints[j];
    const Reply r = bus_.ping(h.id, wait());
    if (!r.has_data())
      throw StopNow{StopReason::setup_failed,
                    fmt::format("{} does not answer a ping ({})", joint_name(j), dynamixel::to_string(r.outcome))};
    const auto model = r.get<std::uint16_t>(0);
    if (model != h.model.model_number)
      throw StopNow{StopReason::setup_failed, fmt::format("{} is model number {}, hardware.yaml says {} ({})",
                                                          joint_name(j), model, h.model.model_number, h.model.name)};
    if (r.outcome == Outcome::hardware_alert) {
      alert_id_ = h.id;
      throw StopNow{StopReason::hardware_error,
                    fmt::format("{} reports a hardware error before the start", joint_name(j))};
    }
  }
  const auto expect_ok = [&](int j, const Reply& r, const char* what) {
    if (!r.has_data())
      throw StopNow{
          StopReason::setup_failed,
          fmt::format(
              "{} refused {}: {}{}", joint_name(j), what, dynamixel::to_string(r.outcome),
              r.outcome == Outcome::error_status ? std::string(" ") + dynamixel::to_string(r.error.number()) : "")};
  };
  for (int j = 0; j < n_; ++j) {
    const std::uint8_t id = ids_[j];
    expect_ok(j, bus_.write(id, xs::kTorqueEnable, 0, wait()), "Torque Enable 0");
    // EEPROM items only when they differ (flash wear).
    const Reply mode = bus_.read(id, xs::kOperatingMode, wait());
    expect_ok(j, mode, "reading Operating Mode");
    if (mode.get<std::uint8_t>(0) != static_cast<std::uint8_t>(xs::OperatingMode::current))
      expect_ok(j, bus_.write(id, xs::kOperatingMode, static_cast<std::int32_t>(xs::OperatingMode::current), wait()),
                "current mode");
    const Reply delay = bus_.read(id, xs::kReturnDelayTime, wait());
    expect_ok(j, delay, "reading Return Delay Time");
    if (delay.get<std::uint8_t>(0) != hw_.return_delay_time)
      expect_ok(j, bus_.write(id, xs::kReturnDelayTime, hw_.return_delay_time, wait()), "Return Delay Time");
    // Bus Watchdog 0 first: it clears a trip an earlier run left (the goal values refuse writes
    // until then). Firmware before v38 has no such item: it matters only when the file asks for it.
    const Reply clear = bus_.write(id, xs::kBusWatchdog, 0, wait());
    if (bus_watchdog_units_ > 0 && !clear.has_data())
      throw StopNow{StopReason::setup_failed,
                    fmt::format("{} refused Bus Watchdog(98) ({}): its firmware may predate v38; hardware.yaml's "
                                "safety.bus_watchdog: 0 runs without the servos' own watchdog",
                                joint_name(j), dynamixel::to_string(clear.outcome))};
    expect_ok(j, bus_.write(id, xs::kGoalCurrent, 0, wait()), "Goal Current 0");
    if (bus_watchdog_units_ > 0)
      expect_ok(
          j, bus_.write(id, xs::kBusWatchdog, bus_watchdog_units_, wait()),
          fmt::format("Bus Watchdog {} ({} ms, safety.bus_watchdog)", bus_watchdog_units_, bus_watchdog_units_ * 20)
              .c_str());
  }
  // The start pose, before torque is on.
  bool fresh = false;
  for (int attempt = 0; attempt < 5 && !fresh; ++attempt) fresh = read_state(wait(), true);
  if (!fresh) throw StopNow{StopReason::setup_failed, "the first sync read of the servos' state failed 5 times"};
  q0_ = q_;
  std::fill(stale_.begin(), stale_.end(), 0);
  plan();
  if (o_.feedforward) check_feedforward();  // throws StopNow before any torque
  for (int j = 0; j < n_; ++j) {
    torque_on_ = true;  // from the first attempt on: a servo may have taken it without answering
    expect_ok(j, bus_.write(ids_[j], xs::kTorqueEnable, 1, wait()), "Torque Enable 1");
  }
}

bool Loop::read_state(Clock::time_point deadline, bool setup) {
  const auto t0 = Clock::now();  // the time the bus takes, on the steady clock whatever the loop's
  const auto replies = bus_.sync_read(ids_, xs::kPresentCurrentVelocityPosition.address,
                                      xs::kPresentCurrentVelocityPosition.size, deadline);
  timing_.read_max = std::max(timing_.read_max, seconds(Clock::now() - t0));
  bool all = true;
  for (int j = 0; j < n_; ++j) {
    const Reply& r = replies[j];
    if (r.outcome == Outcome::hardware_alert) {
      alert_id_ = ids_[j];
      throw StopNow{StopReason::hardware_error, fmt::format("{} raised its hardware alert", joint_name(j))};
    }
    if (!r.has_data() || r.data.size() < xs::kPresentCurrentVelocityPosition.size) {
      all = false;
      ++stale_[j];
      continue;
    }
    stale_[j] = 0;
    const JointHardware& h = hw_.joints[j];
    const double dir = h.direction;
    current_(j) = dir * r.get<std::int16_t>(0) * h.model.current_unit;
    qd_servo_(j) = dir * xs::velocity_to_rad_s(r.get<std::int32_t>(2));
    q_(j) = dir * xs::position_to_rad(r.get<std::int32_t>(6), h.zero);
  }
  if (setup) return all;
  if (!all) {
    ++timing_.read_failures;
    ++stale_cycles_;
    timing_.max_stale = std::max<std::int64_t>(timing_.max_stale, stale_cycles_);
    if (stale_cycles_ >= watchdog_) {
      std::string lost;
      int count = 0;
      for (int j = 0; j < n_; ++j)
        if (stale_[j] >= watchdog_) {
          lost += fmt::format("{}{} (last: {})", lost.empty() ? "" : ", ", joint_name(j),
                              dynamixel::to_string(replies[j].outcome));
          ++count;
        }
      if (count > 0 && count < n_)
        throw StopNow{StopReason::servo_lost,
                      fmt::format("{} stopped answering: {} consecutive failed sync reads", lost, stale_cycles_)};
      throw StopNow{StopReason::watchdog,
                    fmt::format("{} consecutive failed sync reads: the state is {} cycles old (last: {})",
                                stale_cycles_, stale_cycles_, dynamixel::to_string(replies[0].outcome))};
    }
  } else {
    stale_cycles_ = 0;
  }
  return all;
}

void Loop::check_bus_watchdog(Clock::duration away) {
  if (bus_watchdog_units_ <= 0) return;
  const double limit = bus_watchdog_units_ * xs::kBusWatchdogUnit;
  // Only a gap near the limit can have tripped it: then ask the servos (a read, outside the
  // cycle's budget; the cycle is late anyway).
  if (seconds(away) < limit - 2 * T_) return;
  const auto replies = bus_.sync_read(ids_, xs::kBusWatchdog.address, xs::kBusWatchdog.size,
                                      Clock::now() + std::chrono::milliseconds(50));
  for (int j = 0; j < n_; ++j)
    if (replies[j].has_data() && replies[j].get<std::int8_t>(0) == -1)
      throw StopNow{
          StopReason::bus_watchdog,
          fmt::format(
              "{} stopped by its bus watchdog: the loop was away {:.0f} ms, past its {:.0f} ms (safety.bus_watchdog)",
              joint_name(j), 1e3 * seconds(away), 1e3 * limit)};
}

void Loop::check_limits() {
  const Safety& s = hw_.safety;
  for (int j = 0; j < n_; ++j) {
    const JointInfo& J = joints_[j];
    if (q_(j) < J.lower - s.position_tolerance || q_(j) > J.upper + s.position_tolerance)
      throw StopNow{StopReason::position_limit,
                    fmt::format("joint {} {} at {:.4f} rad, beyond its limits [{:.4f}, {:.4f}] (+- {} rad)", j + 1,
                                J.name, q_(j), J.lower, J.upper, s.position_tolerance)};
    if (J.velocity > 0 && std::abs(qd_servo_(j)) > s.velocity_factor * J.velocity)
      throw StopNow{StopReason::velocity_limit, fmt::format("joint {} {} at {:.3f} rad/s, beyond {:.3f} rad/s", j + 1,
                                                            J.name, qd_servo_(j), s.velocity_factor * J.velocity)};
  }
  check_current();
}

void Loop::check_current() {
  const double trip = hw_.safety.current_trip_factor;
  for (int j = 0; j < n_; ++j)
    if (std::abs(current_(j)) > trip * limit_(j))
      throw StopNow{StopReason::current_limit, fmt::format("joint {} {} draws {:.3f} A, beyond {:.3f} A", j + 1,
                                                           joints_[j].name, current_(j), trip * limit_(j))};
}

double Loop::reference(double s) {
  if (s < approach_) {
    const double tau = s / approach_;
    const double p = tau * tau * tau * (10 - 15 * tau + 6 * tau * tau);
    const double v = 30 * tau * tau * (1 - tau) * (1 - tau) / approach_;
    const double a = 60 * tau * (1 - tau) * (1 - 2 * tau) / (approach_ * approach_);
    qr_ = q0_ + p * (qr0_ - q0_);
    qdr_ = v * (qr0_ - q0_);
    qddr_ = a * (qr0_ - q0_);
    return s - approach_ - hw_.safety.pre_roll;
  }
  const double t = s - approach_ - hw_.safety.pre_roll;
  traj_.evaluate(std::max(t, 0.0), qr_, qdr_, qddr_);
  if (t < 0) {
    qdr_.setZero();
    qddr_.setZero();
  }
  return t;
}

void Loop::plan() {
  Eigen::VectorXd tmp(n_);
  traj_.evaluate(0.0, qr0_, tmp, tmp);
  const double distance = (qr0_ - q0_).cwiseAbs().maxCoeff();
  approach_ = distance < 0.01 ? 0.0 : std::max(0.5, 1.875 * distance / hw_.safety.approach_speed);
  const double end = o_.seconds > 0 ? std::min(o_.seconds, traj_.duration()) : traj_.duration();
  k_end_ = std::llround((approach_ + hw_.safety.pre_roll) / T_) + std::llround(end / T_);
}

void Loop::command_torque(control::FfpdController& ctrl, double t) {
  const Eigen::VectorXd& u = ctrl.update(q_, qr_, qdr_, qddr_);
  tau_ = u;
  if (o_.feedforward) {
    o_.feedforward(qr_, qdr_, qddr_, ff_);
    tau_ += ff_ - gains_.inertia.cwiseProduct(qddr_) - gains_.damping.cwiseProduct(qdr_);
  }
  bool saturated = false;
  for (int j = 0; j < n_; ++j) {
    const double raw = std::round(hw_.joints[j].direction * tau_(j) / kt_(j) / unit_(j));
    const double bound = limit_raw_[j];
    // A command that is not a number is a fault upstream (the feedforward model, the
    // controller's state): stopping says so, where a silent 0 or a saturation would not.
    if (!std::isfinite(raw))
      throw StopNow{
          StopReason::invalid_command,
          fmt::format("joint {} {}: the torque command is {} (feedforward {}) at trajectory time {:.3f} s", j + 1,
                      joints_[j].name, tau_(j), o_.feedforward ? fmt::format("{}", ff_(j)) : "none", t)};
    if (std::abs(raw) >= bound) saturated = true;
    command_[j] = static_cast<std::int32_t>(std::clamp(raw, -bound, bound));
  }
  timing_.saturated += saturated;
}

void Loop::log_row(const control::FfpdController& ctrl, double time, double t) {
  traj_time_ = t;
  for (int j = 0; j < n_; ++j) {
    tau_meas_[j] = kt_(j) * current_(j);
    max_error_(j) = std::max(max_error_(j), std::abs(qr_(j) - q_(j)));
  }
  log_->append(time, q_.data(), ctrl.velocity().data(), tau_meas_.data(), qr_.data(), qdr_.data(), qddr_.data());
  // A run whose log cannot be written stops (safely): its rows would be lost.
  if (log_->failed())
    throw StopNow{StopReason::error,
                  fmt::format("{}: {} ({} rows on disk)", log_->path().string(), log_->error(), log_->written())};
}

StopNow Loop::loop() {
  const double distance = (qr0_ - q0_).cwiseAbs().maxCoeff();
  const double end = o_.seconds > 0 ? std::min(o_.seconds, traj_.duration()) : traj_.duration();
  const std::int64_t k_traj0 = std::llround((approach_ + hw_.safety.pre_roll) / T_);
  const std::int64_t k_end = k_end_;
  control::FfpdController& ctrl = ctrl_.emplace(gains_);
  ctrl.reset(q_);
  if (o_.verbose)
    std::fprintf(stderr, "control: %s, %.3f s (approach %.2f s over %.3f rad, hold %.2f s), period %.1f ms\n",
                 traj_.name.c_str(), end, approach_, distance, hw_.safety.pre_roll, T_ * 1e3);

  const auto T = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(T_));
  const auto start = clock_.now() + T;
  Clock::time_point previous_wake{};
  double period_sum = 0, period_sq = 0, latency_sum = 0, work_sum = 0;
  std::int64_t periods = 0;
  timing_.period_min = 1e9;
  for (std::int64_t k = 0;; ++k) {
    const auto deadline = start + k * T;
    clock_.sleep_until(deadline, *stop_, stops_seen_);
    const auto wake = clock_.now();
    ++timing_.cycles;
    const double latency = seconds(wake - deadline);
    latency_sum += latency;
    timing_.latency_max = std::max(timing_.latency_max, latency);
    if (previous_wake != Clock::time_point{}) {
      const double p = seconds(wake - previous_wake);
      period_sum += p;
      period_sq += p * p;
      ++periods;
      timing_.period_min = std::min(timing_.period_min, p);
      timing_.period_max = std::max(timing_.period_max, p);
      timing_.jitter_max = std::max(timing_.jitter_max, std::abs(p - T_));
    }
    if (previous_wake != Clock::time_point{}) check_bus_watchdog(wake - previous_wake);
    previous_wake = wake;
    period_stats_ = {period_sum, period_sq, latency_sum, work_sum, static_cast<double>(periods)};
    if (stop_->load(std::memory_order_relaxed) > stops_seen_) {
      const std::string sig = stop_ == &stop_flag() ? last_stop_signal() : "";
      return {StopReason::signal, sig.empty() ? "stop requested" : "stop requested (" + sig + ")"};
    }

    const bool fresh = read_state(clock_.io_deadline(std::max(deadline + T * 8 / 10, wake + T / 2)));
    // Every cycle, on what is known: a servo that did not answer keeps its last state (its
    // staleness is counted by the watchdog), the others are current.
    check_limits();
    const double t = reference(k * T_);
    if (o_.timeline) o_.timeline->store(t, std::memory_order_relaxed);
    command_torque(ctrl, t);
    if (!bus_.sync_write(ids_, xs::kGoalCurrent, dynamixel::Span<const std::int32_t>(command_.data(), command_.size()),
                         clock_.io_deadline(std::max(deadline + T * 95 / 100, clock_.now() + T / 4))))
      ++timing_.write_failures;

    if (t >= -1e-9 && fresh) log_row(ctrl, seconds(wake - (start + k_traj0 * T)), t);
    const auto done = clock_.now();
    const double work = seconds(done - wake);
    work_sum += work;
    timing_.work_max = std::max(timing_.work_max, work);
    period_stats_[3] = work_sum;
    if (k >= k_end) return {StopReason::completed, fmt::format("the trajectory ran to {:.3f} s", end)};
    if (done > deadline + T) {
      ++timing_.overruns;
      // Behind by more than a period: skip the deadlines already past (the reference follows
      // the clock, so the arm is not asked to catch up).
      while (start + (k + 1) * T + T / 2 < done && k + 1 < k_end) {
        ++k;
        ++timing_.skipped;
      }
    }
  }
}

void Loop::finish_timing() {
  const double periods = period_stats_[4];
  if (periods > 0) {
    timing_.period_mean = period_stats_[0] / periods;
    timing_.period_std =
        std::sqrt(std::max(0.0, period_stats_[1] / periods - timing_.period_mean * timing_.period_mean));
  }
  if (timing_.cycles > 0) {
    timing_.latency_mean = period_stats_[2] / timing_.cycles;
    timing_.work_mean = period_stats_[3] / timing_.cycles;
  }
  if (timing_.period_min > 1e8) timing_.period_min = 0;
}

}  // namespace symoro::hardware::detail
