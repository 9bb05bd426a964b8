// The DYNAMIXEL driver end to end: SerialPort and Bus on a real pseudo-terminal, against the
// virtual CRANE-X7 servo chain (VirtualBus + RotorBackend). Motion is checked against the
// rotor's closed-form step response written out here (not the backend's integrator); faults are
// checked for their typed outcome, a bounded return time, and recovery.
#include <symoro/dynamixel/bus.hpp>
#include <symoro/dynamixel/serial_port.hpp>
#include <symoro/dynamixel/virtual_bus.hpp>

#include <fcntl.h>
#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

// Allocation counter for this thread (the control loop's), to check "no allocation per cycle".
namespace {
thread_local std::size_t t_allocations = 0;
}
void* operator new(std::size_t size) {
  ++t_allocations;
  if (void* p = std::malloc(size ? size : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace symoro::dynamixel {
namespace {

namespace xs = xseries;
using Clock = std::chrono::steady_clock;
using std::chrono::microseconds;

const std::uint8_t kIds[] = {2, 3, 4, 5, 6, 7, 8, 9};
constexpr std::size_t kServos = 8;

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

std::vector<RotorBackend::Rotor> rotors() {
  std::vector<RotorBackend::Rotor> r(kServos);
  for (std::size_t i = 0; i < kServos; ++i) {
    r[i].inertia = 0.04 + 0.005 * i;
    r[i].damping = 0.1;
    r[i].torque_constant = i == 1 ? 3.1317 : 2.3179;  // axis 2 is the XM540-W270
  }
  return r;
}

// Patient options for the functional tests: the machine running them may be loaded (the virtual
// servos are a thread that can wait milliseconds for a core); timing is the 1 kHz test's job.
BusOptions patient() { return BusOptions{microseconds(500), microseconds(10'000), 2}; }

struct Rig {
  explicit Rig(BusOptions options = patient())
      : virt(crane_x7_servos(), std::make_unique<RotorBackend>(rotors())),
        port(virt.device(), 3'000'000),
        bus(port, options) {}
  VirtualBus virt;
  SerialPort port;
  Bus bus;
};

// Fault tests: no retry (so that the fault shows), a margin that tolerates a loaded machine.
BusOptions no_retry() { return BusOptions{microseconds(500), microseconds(5'000), 0}; }

// The bound a failing call must return within: 5 times its own attempt timeout.
Clock::duration bound(const Bus& bus, std::size_t replies, std::size_t params) {
  return 5 * bus.attempt_timeout(64, replies, params);
}

void enable_current_mode(Bus& bus) {
  for (std::uint8_t id : kIds) {
    ASSERT_EQ(bus.write(id, xs::kOperatingMode, 0).outcome, Outcome::ok);
    ASSERT_EQ(bus.write(id, xs::kTorqueEnable, 1).outcome, Outcome::ok);
  }
}

// ---- SerialPort -------------------------------------------------------------------------------

TEST(SerialPort, UnsupportedBaudNamesDeviceAndRate) {
  VirtualBus virt(crane_x7_servos(), std::make_unique<RotorBackend>(rotors()));
  try {
    SerialPort port(virt.device(), 4'500'000);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(virt.device()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("4500000"), std::string::npos) << e.what();
  }
  for (std::uint32_t baud : {57'600u, 1'000'000u, 2'000'000u, 3'000'000u, 4'000'000u}) {
    SerialPort port(virt.device(), baud);  // a pty accepts them all
    EXPECT_EQ(port.baud(), baud);
  }
}

TEST(SerialPort, OpenErrorNamesDeviceAndErrno) {
  try {
    SerialPort port("/dev/symoro-no-such-tty", 3'000'000);
    FAIL() << "no error";
  } catch (const SerialError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("/dev/symoro-no-such-tty"), std::string::npos) << what;
    EXPECT_NE(what.find("No such file"), std::string::npos) << what;
  }
}

TEST(SerialPort, ReadHonoursDeadlineAndWritesArrive) {
  const int master = ::posix_openpt(O_RDWR | O_NOCTTY);
  ASSERT_GE(master, 0);
  ASSERT_EQ(::grantpt(master), 0);
  ASSERT_EQ(::unlockpt(master), 0);
  SerialPort port(::ptsname(master), 1'000'000);
  std::uint8_t buf[64];
  const auto t0 = Clock::now();
  EXPECT_EQ(port.read_some(buf, t0 + microseconds(3000)), 0u);
  const auto waited = Clock::now() - t0;
  EXPECT_GE(waited, microseconds(3000));
  EXPECT_LT(waited, microseconds(50'000));

  const std::uint8_t hello[] = {1, 2, 0xFF, 0, 3};
  ASSERT_EQ(::write(master, hello, sizeof hello), 5);
  std::size_t got = 0;
  while (got < 5) {
    const std::size_t n = port.read_some(Span<std::uint8_t>(buf + got, 64 - got), Clock::now() + microseconds(100'000));
    ASSERT_GT(n, 0u);
    got += n;
  }
  EXPECT_TRUE(std::equal(hello, hello + 5, buf));  // raw: no CR/LF or 0xFF translation

  EXPECT_TRUE(port.write_all(ByteView(hello, 5), Clock::now() + microseconds(100'000)));
  std::uint8_t back[8];
  std::size_t n = 0;
  for (int i = 0; i < 100 && n < 5; ++i) {
    const ssize_t r = ::read(master, back + n, sizeof back - n);
    if (r > 0)
      n += static_cast<std::size_t>(r);
    else
      std::this_thread::sleep_for(microseconds(1000));
  }
  EXPECT_EQ(n, 5u);
  EXPECT_TRUE(std::equal(hello, hello + 5, back));
  ::close(master);
}

// ---- Bus against the virtual chain ------------------------------------------------------------

TEST(DynamixelBus, PingsEveryServoAndReadsModelNumbers) {
  Rig rig;
  for (std::uint8_t id : kIds) {
    const Reply r = rig.bus.ping(id);
    ASSERT_EQ(r.outcome, Outcome::ok) << int(id) << ": " << to_string(r.outcome);
    const std::uint16_t expected = id == 3 ? 1120 : 1020;
    EXPECT_EQ(r.get<std::uint16_t>(0), expected);
    const Reply m = rig.bus.read(id, xs::kModelNumber);
    ASSERT_EQ(m.outcome, Outcome::ok);
    EXPECT_EQ(m.get<std::uint16_t>(), expected);
    EXPECT_NE(xs::find_model(m.get<std::uint16_t>()), nullptr);
  }
  EXPECT_EQ(rig.bus.ping(42).outcome, Outcome::timeout);  // nobody there

  const std::vector<PingReply> all = rig.bus.ping_all();
  ASSERT_EQ(all.size(), kServos);
  for (std::size_t i = 0; i < kServos; ++i) EXPECT_EQ(all[i].id, kIds[i]);
  EXPECT_EQ(all[1].model_number, 1120);
}

TEST(DynamixelBus, WritesTorqueEnableAndOperatingModeWithProtocolErrors) {
  Rig rig;
  const std::uint8_t id = 4;
  EXPECT_EQ(rig.bus.write(id, xs::kOperatingMode, 0).outcome, Outcome::ok);
  EXPECT_EQ(rig.bus.read(id, xs::kOperatingMode).get<std::uint8_t>(), 0);
  EXPECT_EQ(rig.bus.write(id, xs::kTorqueEnable, 1).outcome, Outcome::ok);
  EXPECT_EQ(rig.bus.read(id, xs::kTorqueEnable).get<std::uint8_t>(), 1);

  // EEPROM with torque on: access error, nothing changed.
  Reply r = rig.bus.write(id, xs::kOperatingMode, 3);
  EXPECT_EQ(r.outcome, Outcome::error_status);
  EXPECT_EQ(r.error.number(), ErrorNumber::access_error);
  EXPECT_EQ(rig.virt.value(id, xs::kOperatingMode), 0);
  r = rig.bus.write(id, xs::kReturnDelayTime, 10);
  EXPECT_EQ(r.error.number(), ErrorNumber::access_error);

  // Goal Current beyond Current Limit(38) (1193 on an XM430-W350): data range error.
  r = rig.bus.write(id, xs::kGoalCurrent, 1194);
  EXPECT_EQ(r.outcome, Outcome::error_status);
  EXPECT_EQ(r.error.number(), ErrorNumber::data_range_error);
  EXPECT_EQ(rig.bus.write(id, xs::kGoalCurrent, -1193).outcome, Outcome::ok);
  EXPECT_EQ(rig.bus.write(3, xs::kGoalCurrent, 2000).outcome, Outcome::ok);  // XM540: 2047
  // Undefined values and read-only items.
  EXPECT_EQ(rig.bus.write(id, xs::kTorqueEnable, 2).error.number(), ErrorNumber::data_range_error);
  EXPECT_EQ(rig.bus.write(id, xs::kPresentPosition, 0).error.number(), ErrorNumber::access_error);
  EXPECT_EQ(rig.bus.write(id, xs::kGoalCurrent.address, ByteView(kIds, 1)).error.number(),
            ErrorNumber::data_length_error);

  // Torque off: EEPROM writable again; an undefined mode is a range error.
  EXPECT_EQ(rig.bus.write(id, xs::kTorqueEnable, 0).outcome, Outcome::ok);
  EXPECT_EQ(rig.bus.write(id, xs::kOperatingMode, 2).error.number(), ErrorNumber::data_range_error);
  EXPECT_EQ(rig.bus.write(id, xs::kOperatingMode, 3).outcome, Outcome::ok);
  EXPECT_EQ(rig.virt.value(id, xs::kOperatingMode), 3);
}

TEST(DynamixelBus, GoalCurrentActsOnlyWithTorqueOnInCurrentMode) {
  Rig rig;
  const std::uint8_t id = 2;
  auto present_current = [&] {
    std::this_thread::sleep_for(microseconds(2000));
    return rig.bus.read(id, xs::kPresentCurrent).get<std::int16_t>();
  };
  ASSERT_EQ(rig.bus.write(id, xs::kGoalCurrent, 100).outcome, Outcome::ok);
  EXPECT_EQ(present_current(), 0);  // torque off, position mode
  ASSERT_EQ(rig.bus.write(id, xs::kTorqueEnable, 1).outcome, Outcome::ok);
  EXPECT_EQ(present_current(), 0);  // torque on, but position mode (3)
  ASSERT_EQ(rig.bus.write(id, xs::kTorqueEnable, 0).outcome, Outcome::ok);
  ASSERT_EQ(rig.bus.write(id, xs::kOperatingMode, 0).outcome, Outcome::ok);
  EXPECT_EQ(present_current(), 0);  // current mode, torque off
  ASSERT_EQ(rig.bus.write(id, xs::kTorqueEnable, 1).outcome, Outcome::ok);
  EXPECT_EQ(present_current(), 100);
  std::this_thread::sleep_for(microseconds(20'000));
  EXPECT_GT(rig.bus.read(id, xs::kPresentVelocity).get<std::int32_t>(), 0);
}

// The 1 kHz cycle: sync write Goal Current, sync read Present Current/Velocity/Position.
TEST(DynamixelBus, ControlLoopFollowsClosedFormAt1kHz) {
  Rig rig;
  enable_current_mode(rig.bus);
  rig.bus.set_options(BusOptions{});  // the defaults: 0.5 ms per status + 1 ms, one retry
  const std::int32_t goal[kServos] = {40, -30, 25, -20, 35, -45, 30, -25};
  const std::vector<RotorBackend::Rotor> rot = rotors();

  constexpr int kCycles = 2500;
  struct Sample {
    Clock::time_point write_start, read_start, read_end;
    bool ok;
    std::int16_t current[kServos];
    std::int32_t velocity[kServos], position[kServos];
  };
  std::vector<Sample> samples(kCycles);
  const std::size_t allocations_before_warmup = t_allocations;
  std::size_t allocations_after_warmup = 0;
  const auto period = microseconds(1000);
  auto next = Clock::now() + period;
  int overruns = 0;
  for (int k = 0; k < kCycles; ++k) {
    if (k == 10) allocations_after_warmup = t_allocations;
    Sample& s = samples[k];
    const Clock::time_point deadline = next + period;  // the loop's budget: one period ahead
    s.write_start = Clock::now();
    const bool sent = rig.bus.sync_write(kIds, xs::kGoalCurrent, goal, deadline);
    s.read_start = Clock::now();
    const Span<const Reply> replies = rig.bus.sync_read(kIds, xs::kPresentCurrentVelocityPosition.address,
                                                        xs::kPresentCurrentVelocityPosition.size, deadline);
    s.read_end = Clock::now();
    s.ok = sent;
    for (std::size_t i = 0; i < kServos; ++i) {
      s.ok = s.ok && replies[i].outcome == Outcome::ok;
      s.current[i] = replies[i].get<std::int16_t>(0);
      s.velocity[i] = replies[i].get<std::int32_t>(2);
      s.position[i] = replies[i].get<std::int32_t>(6);
    }
    std::this_thread::sleep_until(next);
    if (Clock::now() > next + period) {
      ++overruns;
      next = Clock::now();
    }
    next += period;
  }
  const std::size_t loop_allocations = t_allocations - allocations_after_warmup;
  (void)allocations_before_warmup;
  EXPECT_EQ(loop_allocations, 0u) << "allocations per cycle after warm-up";

  // Closed form of J w' = kt i - b w from rest at t = 0: w = w_end (1 - e^(-t/T)),
  // q = w_end (t - T (1 - e^(-t/T))), T = J/b.
  auto response = [](const RotorBackend::Rotor& r, double amps, double t, double& q, double& w) {
    const double T = r.inertia / r.damping, w_end = r.torque_constant * amps / r.damping;
    const double e = 1 - std::exp(-t / T);
    w = w_end * e;
    q = r.position + w_end * (t - T * e);
  };
  // The step was applied between the first write's start and the first read's end; sample k
  // was taken between its read's start and end. Both responses are monotone in t, so the value
  // lies between those at the extreme elapsed times (plus half a count of quantization).
  int failed = 0, checked = 0;
  for (int k = 1; k < kCycles; ++k) {
    const Sample& s = samples[k];
    if (!s.ok || !samples[0].ok) {
      ++failed;
      continue;
    }
    const double lo = std::max(0.0, seconds(s.read_start - samples[0].read_end));
    const double hi = seconds(s.read_end - samples[0].write_start);
    for (std::size_t i = 0; i < kServos; ++i) {
      const double amps = goal[i] * xs::kCurrentUnit;
      double q_lo, w_lo, q_hi, w_hi;
      response(rot[i], amps, lo, q_lo, w_lo);
      response(rot[i], amps, hi, q_hi, w_hi);
      const double q = xs::position_to_rad(s.position[i]);
      const double w = xs::velocity_to_rad_s(s.velocity[i]);
      const double eq = 0.5 * xs::kPositionUnit + 1e-9, ew = 0.5 * xs::kVelocityUnit + 1e-9;
      EXPECT_EQ(s.current[i], goal[i]);
      ASSERT_GE(q, std::min(q_lo, q_hi) - eq) << "cycle " << k << " joint " << i;
      ASSERT_LE(q, std::max(q_lo, q_hi) + eq) << "cycle " << k << " joint " << i;
      ASSERT_GE(w, std::min(w_lo, w_hi) - ew) << "cycle " << k << " joint " << i;
      ASSERT_LE(w, std::max(w_lo, w_hi) + ew) << "cycle " << k << " joint " << i;
      ++checked;
    }
  }
  // The joints really moved: after 2.5 s the slowest has turned by more than a radian.
  for (std::size_t i = 0; i < kServos; ++i)
    EXPECT_GT(std::abs(xs::position_to_rad(samples[kCycles - 1].position[i])), 1.0);
  // A cycle fails when the virtual servos' thread waited for a core past the cycle's deadline
  // (a loaded test machine); the loop goes on, which is the point.
  EXPECT_LE(failed, kCycles / 10) << "cycles with a failed transaction";
  EXPECT_GT(checked, 0);

  // Transaction time: sync write + sync read of the cycle.
  std::vector<double> us;
  for (const Sample& s : samples) us.push_back(1e6 * seconds(s.read_end - s.write_start));
  std::sort(us.begin(), us.end());
  const BusStats& st = rig.bus.stats();
  std::printf(
      "[ timing   ] %d cycles at 1 kHz, transaction (sync write + sync read of 8 servos): median "
      "%.0f us, p99 %.0f us, max %.0f us; overruns %d, failed cycles %d; timeouts %llu, CRC %llu, "
      "retries %llu\n",
      kCycles, us[us.size() / 2], us[us.size() * 99 / 100], us.back(), overruns, failed,
      static_cast<unsigned long long>(st.timeouts), static_cast<unsigned long long>(st.crc_errors),
      static_cast<unsigned long long>(st.retries));
}

// ---- Faults ------------------------------------------------------------------------------------

TEST(DynamixelBusFaults, CorruptedCrcIsReportedThenRecovers) {
  Rig rig(no_retry());
  rig.virt.corrupt_replies(1);
  auto t0 = Clock::now();
  Reply r = rig.bus.read(5, xs::kPresentPosition);
  EXPECT_EQ(r.outcome, Outcome::bad_crc);
  EXPECT_LT(Clock::now() - t0, bound(rig.bus, 1, 4));
  EXPECT_EQ(rig.bus.stats().crc_errors, 1u);
  EXPECT_EQ(rig.bus.read(5, xs::kPresentPosition).outcome, Outcome::ok);

  // In a sync read: the corrupted reply is the first servo's; the others arrive intact.
  rig.virt.corrupt_replies(1);
  t0 = Clock::now();
  Span<const Reply> rs = rig.bus.sync_read(kIds, 126, 10);
  EXPECT_LT(Clock::now() - t0, bound(rig.bus, kServos, 80));
  EXPECT_EQ(rs[0].outcome, Outcome::bad_crc);
  for (std::size_t i = 1; i < kServos; ++i) EXPECT_EQ(rs[i].outcome, Outcome::ok) << i;
  rs = rig.bus.sync_read(kIds, 126, 10);
  for (const Reply& x : rs) EXPECT_EQ(x.outcome, Outcome::ok);

  // With a retry allowed, the failed ID alone is asked again and the call succeeds.
  rig.bus.set_options(patient());
  rig.virt.corrupt_replies(1);
  rs = rig.bus.sync_read(kIds, 126, 10);
  for (const Reply& x : rs) EXPECT_EQ(x.outcome, Outcome::ok);
  EXPECT_GE(rig.bus.stats().retries, 1u);
}

TEST(DynamixelBusFaults, DroppedReplyTimesOutWithinItsDeadlineThenRecovers) {
  Rig rig(no_retry());
  rig.virt.drop_replies(1);
  auto t0 = Clock::now();
  Reply r = rig.bus.read(7, xs::kPresentVelocity);
  const auto took = Clock::now() - t0;
  EXPECT_EQ(r.outcome, Outcome::timeout);
  EXPECT_GE(took, rig.bus.options().margin);  // it did wait for the reply
  EXPECT_LT(took, bound(rig.bus, 1, 4));
  EXPECT_EQ(rig.bus.stats().timeouts, 1u);
  EXPECT_EQ(rig.bus.read(7, xs::kPresentVelocity).outcome, Outcome::ok);

  rig.virt.drop_replies(1);
  t0 = Clock::now();
  Span<const Reply> rs = rig.bus.sync_read(kIds, 126, 10);
  EXPECT_LT(Clock::now() - t0, bound(rig.bus, kServos, 80));
  EXPECT_EQ(rs[0].outcome, Outcome::timeout);
  for (std::size_t i = 1; i < kServos; ++i) EXPECT_EQ(rs[i].outcome, Outcome::ok) << i;
  EXPECT_EQ(rig.bus.ping(2).outcome, Outcome::ok);
}

TEST(DynamixelBusFaults, DeadServoTimesOutOthersAnswerAndItComesBack) {
  Rig rig(no_retry());
  rig.virt.set_dead(5, true);
  auto t0 = Clock::now();
  EXPECT_EQ(rig.bus.ping(5).outcome, Outcome::timeout);
  EXPECT_LT(Clock::now() - t0, bound(rig.bus, 1, 3));
  for (int round = 0; round < 3; ++round) {
    t0 = Clock::now();
    const Span<const Reply> rs = rig.bus.sync_read(kIds, 126, 10);
    EXPECT_LT(Clock::now() - t0, bound(rig.bus, kServos, 80));
    for (std::size_t i = 0; i < kServos; ++i)
      EXPECT_EQ(rs[i].outcome, kIds[i] == 5 ? Outcome::timeout : Outcome::ok) << i;
  }
  // The caller's budget wins over the bus's own timeout, and leaves no room for retries.
  rig.bus.set_options(BusOptions{microseconds(500), microseconds(1000), 3});
  const std::uint64_t retries = rig.bus.stats().retries;
  t0 = Clock::now();
  EXPECT_EQ(rig.bus.ping(5, t0 + microseconds(300)).outcome, Outcome::timeout);
  EXPECT_LT(Clock::now() - t0, 5 * microseconds(300));
  EXPECT_EQ(rig.bus.stats().retries, retries);

  rig.virt.set_dead(5, false);
  EXPECT_EQ(rig.bus.ping(5).outcome, Outcome::ok);
  for (const Reply& r : rig.bus.sync_read(kIds, 126, 10)) EXPECT_EQ(r.outcome, Outcome::ok);
}

TEST(DynamixelBusFaults, HardwareErrorSetsAlertBitUntilReboot) {
  Rig rig(no_retry());
  enable_current_mode(rig.bus);
  rig.virt.set_hardware_error(4, xs::hardware_error::kOverload);
  auto t0 = Clock::now();
  const Span<const Reply> rs = rig.bus.sync_read(kIds, 126, 10);
  EXPECT_LT(Clock::now() - t0, bound(rig.bus, kServos, 80));
  for (std::size_t i = 0; i < kServos; ++i) {
    EXPECT_EQ(rs[i].outcome, kIds[i] == 4 ? Outcome::hardware_alert : Outcome::ok) << i;
    EXPECT_TRUE(rs[i].has_data());  // the data is still valid
  }
  EXPECT_TRUE(rs[2].error.alert());
  const Reply status = rig.bus.read(4, xs::kHardwareErrorStatus);
  EXPECT_EQ(status.outcome, Outcome::hardware_alert);
  EXPECT_EQ(status.get<std::uint8_t>(), xs::hardware_error::kOverload);
  EXPECT_EQ(rig.bus.read(4, xs::kTorqueEnable).get<std::uint8_t>(), 0);  // shut down
  EXPECT_GE(rig.bus.stats().alerts, 2u);

  EXPECT_EQ(rig.bus.reboot(4).outcome, Outcome::ok);
  EXPECT_EQ(rig.bus.read(4, xs::kHardwareErrorStatus).outcome, Outcome::ok);
  EXPECT_EQ(rig.bus.write(4, xs::kTorqueEnable, 1).outcome, Outcome::ok);
  for (const Reply& r : rig.bus.sync_read(kIds, 126, 10)) EXPECT_EQ(r.outcome, Outcome::ok);
}

TEST(DynamixelBusFaults, ReplyFromAnotherIdIsWrongId) {
  Rig rig(no_retry());
  rig.virt.set_reply_id(6, 20);
  auto t0 = Clock::now();
  EXPECT_EQ(rig.bus.read(6, xs::kPresentPosition).outcome, Outcome::wrong_id);
  EXPECT_LT(Clock::now() - t0, bound(rig.bus, 1, 4));
  const Span<const Reply> rs = rig.bus.sync_read(kIds, 126, 10);
  for (std::size_t i = 0; i < kServos; ++i)
    EXPECT_EQ(rs[i].outcome, kIds[i] == 6 ? Outcome::wrong_id : Outcome::ok) << i;
  EXPECT_GE(rig.bus.stats().wrong_ids, 2u);
  rig.virt.set_reply_id(6, 6);
  EXPECT_EQ(rig.bus.read(6, xs::kPresentPosition).outcome, Outcome::ok);
}

TEST(DynamixelBus, BulkReadAndReturnDelay) {
  Rig rig;
  const BulkReadItem items[] = {
      {2, xs::kModelNumber.address, 2}, {3, xs::kModelNumber.address, 2}, {9, xs::kPresentPosition.address, 4}};
  const Span<const Reply> rs = rig.bus.bulk_read(items);
  ASSERT_EQ(rs.size(), 3u);
  EXPECT_EQ(rs[0].get<std::uint16_t>(), 1020);
  EXPECT_EQ(rs[1].get<std::uint16_t>(), 1120);
  EXPECT_EQ(rs[2].get<std::int32_t>(), xs::kCenterPosition);

  // Return Delay Time(9) = 250 (500 us, the factory value): the reply waits that long.
  ASSERT_EQ(rig.bus.write(8, xs::kReturnDelayTime, 250).outcome, Outcome::ok);
  const auto t0 = Clock::now();
  EXPECT_EQ(rig.bus.ping(8).outcome, Outcome::ok);
  EXPECT_GE(Clock::now() - t0, microseconds(500));
}

}  // namespace
}  // namespace symoro::dynamixel
