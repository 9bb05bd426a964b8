// The rig of the controller tests: run_control (SerialPort + Bus) over a real pseudo-terminal
// against the virtual CRANE-X7 chain whose servos drive the digital twin's plant
// (TwinServoBackend); the HardwareControl fixture runs a trajectory on a fresh rig and injects
// faults on the controller's own timeline. Included by test_hardware_control.cpp (tracking,
// bus faults) and test_hardware_stops.cpp (limits, signals, the hold at a stop).
#pragma once

#include <symoro/crane_x7.hpp>
#include <symoro/dynamixel/bus.hpp>
#include <symoro/dynamixel/serial_port.hpp>
#include <symoro/dynamixel/virtual_bus.hpp>
#include <symoro/hardware/config.hpp>
#include <symoro/hardware/controller.hpp>
#include <symoro/hardware/loop_clock.hpp>
#include <symoro/io/parameters_yaml.hpp>
#include <symoro/robot/compiled_model.hpp>
#include <symoro/twin_bus/twin_servo_backend.hpp>
#include <symoro/io/log.hpp>
#include <symoro/io/log_stream.hpp>
#include <symoro/io/number_text.hpp>
#include <symoro/trajectory/design.hpp>
#include <symoro/twin/simulator.hpp>
#include <symoro/twin/tracking_bound.hpp>

#include <fcntl.h>
#include <pthread.h>
#include <sys/stat.h>
#include <sched.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <thread>

#include <fmt/format.h>
#include <gtest/gtest.h>

namespace symoro::hardware {
namespace {

using twin_bus::TwinServoBackend;
using twin_bus::virtual_servos;

using Model = crane_x7::Model;
namespace xs = dynamixel::xseries;
constexpr int kWatchdog = 20;
constexpr double kDeg = 180 / 3.14159265358979323846;

const std::filesystem::path kRobot = std::filesystem::path(SYMORO_ROBOTS_DIR) / "crane_x7";

std::vector<JointInfo> joints() { return {Model::joints.begin(), Model::joints.end()}; }

twin::TwinConfig ideal_twin() {
  twin::TwinConfig c = twin::read_twin_config(kRobot / "twin.yaml", Model::nq);
  c.effects.disable_all();
  return c;
}

// The first segments of a designed trajectory, covering at least `seconds`.
trajectory::Trajectory first_seconds(const std::string& name, double seconds) {
  trajectory::Trajectory t = trajectory::TrajectoryDesign::read(kRobot / "trajectories.yaml", joints()).build(name);
  std::size_t keep = 0;
  while (keep < t.segments.size() && t.segments[keep].start < seconds) ++keep;
  t.segments.resize(keep);
  return t;
}

std::filesystem::path temp_dir() {
  const auto d = std::filesystem::temp_directory_path() / ("symoro_hw_" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  return d;
}

// SCHED_FIFO for this thread while it lives, when the system allows it: the virtual bus's
// thread, created meanwhile, inherits it, and the loop asks for it too (ControlOptions), so that
// the emulated arm and its controller keep their 1 kHz on a machine shared with compilers.
struct Realtime {
  Realtime() {
    pthread_getschedparam(pthread_self(), &policy, &param);
    sched_param p{};
    p.sched_priority = kPriority;
    on = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p) == 0;
  }
  ~Realtime() { release(); }
  void release() {
    if (on) pthread_setschedparam(pthread_self(), policy, &param);
    on = false;
  }
  static constexpr int kPriority = 20;
  int policy = 0;
  sched_param param{};
  bool on = false;
};

// The arm and the loop run on the rig's stepped clock (hardware/loop_clock.hpp; run() gives it
// to the loop): no time passes on the arm while the host is slow, so a loaded machine cannot move
// it between cycles. Paced (the default), the loop still keeps real time, so that signals and
// fault injectors meet it when they would meet the arm; unpaced it runs as fast as the bus. On
// the wall clock the arm integrates in real time (a controller in another process).
enum class RigClock { paced, unpaced, wall };

struct Rig {
  Rig(const twin::TwinConfig& twin, const HardwareConfig& h, const trajectory::Trajectory& traj,
      RigClock mode = RigClock::paced)
      : hw(h),
        realtime(),
        clock(mode == RigClock::paced),
        virt(
            virtual_servos(h), make_backend(twin, h, traj),
            mode == RigClock::wall ? std::function<double()>() : [this] { return clock.seconds(); }),
        port(virt.device(), h.baud),
        bus(port) {
    realtime.release();  // the virtual servos' thread keeps it
  }

  std::unique_ptr<dynamixel::ServoBackend> make_backend(const twin::TwinConfig& twin, const HardwareConfig& h,
                                                        const trajectory::Trajectory& traj) {
    Eigen::VectorXd q(Model::nq), qd(Model::nq), qdd(Model::nq);
    traj.evaluate(0, q, qd, qdd);
    auto b = std::make_unique<TwinServoBackend>(symoro::robot::compiled_model<Model>(), twin, h, q);
    backend = b.get();
    return b;
  }

  // Every servo: Torque Enable 0 and Goal Current 0 in its control table.
  void expect_safe(std::uint8_t except = 0) const {
    for (std::uint8_t id : hw.ids()) {
      if (id == except) continue;
      EXPECT_EQ(virt.value(id, xs::kTorqueEnable), 0) << "servo " << int(id);
      EXPECT_EQ(virt.value(id, xs::kGoalCurrent), 0) << "servo " << int(id);
    }
  }

  HardwareConfig hw;
  Realtime realtime;  // while the virtual bus's thread starts
  SteppedClock clock;
  TwinServoBackend* backend = nullptr;
  dynamixel::VirtualBus virt;
  dynamixel::SerialPort port;
  dynamixel::Bus bus;
};

class HardwareControl : public ::testing::Test {
 protected:
  void SetUp() override {
    twin_ = ideal_twin();
    hw_ = read_hardware_config(kRobot / "hardware.yaml", joints());
    // The bundled file holds for 2 s at a stop; a short hold keeps the fault tests short (the
    // hold itself is tested below with its own time).
    EXPECT_EQ(hw_.safety.at_stop, StopAction::hold);
    hw_.safety.hold_time = 0.2;
    gains_ = twin::controller_gains(twin_);
    dir_ = temp_dir();
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  ControlOptions options() const {
    ControlOptions o;
    o.robot = "crane_x7";
    o.source = "twin";
    o.notes = "test: virtual bus + twin backend";
    // The virtual servos are a thread on a shared, loaded machine: it may miss a few ms.
    o.watchdog_cycles = kWatchdog;
    o.realtime_priority = Realtime::kPriority + 1;
    return o;
  }

  // Runs `traj` on a fresh rig; `inject(rig)` runs on another thread once the controller's
  // trajectory time reaches `after` s (its own timeline: the approach and pre-roll before t = 0
  // take a machine-dependent wall time, so a wall-clock trigger could land before the start).
  ControlResult run(Rig& rig, const trajectory::Trajectory& traj, const std::string& csv, ControlOptions o,
                    double after = -1, std::function<void(Rig&)> inject = {},
                    std::vector<JointInfo> limits = joints()) {
    std::atomic<double> timeline{-1e9};
    std::atomic<bool> finished{false};
    o.timeline = &timeline;
    if (!o.clock) o.clock = &rig.clock;
    std::thread injector;
    if (inject)
      injector = std::thread([&rig, &timeline, &finished, after, inject] {
        while (!finished.load() && timeline.load() < after) std::this_thread::sleep_for(std::chrono::microseconds(200));
        if (!finished.load()) inject(rig);
      });
    ControlResult r = run_control(rig.bus, hw_, limits, gains_, traj, csv, o);
    finished = true;
    if (injector.joinable()) injector.join();
    return r;
  }

  // The log on disk is complete and readable, ends where the run stopped, and says what was
  // done at the stop. A run stopped before the trajectory's first row leaves no samples: its
  // sidecar is readable and read_log's refusal gives the notes.
  void expect_log(const ControlResult& r, const std::string& csv) {
    EXPECT_FALSE(r.at_stop.empty());
    if (r.rows == 0) {
      const io::LogMetadata meta = io::read_log_metadata(csv);
      EXPECT_NE(meta.notes.find(std::string("stop: ") + to_string(r.reason)), std::string::npos) << meta.notes;
      EXPECT_NE(meta.notes.find("at stop: " + r.at_stop), std::string::npos) << meta.notes;
      try {
        io::read_log(csv);
        ADD_FAILURE() << "a log without samples was read";
      } catch (const DataError& e) {
        EXPECT_NE(std::string(e.what()).find(std::string("stop: ") + to_string(r.reason)), std::string::npos)
            << e.what();
      }
      return;
    }
    io::Log log;
    ASSERT_NO_THROW(log = io::read_log(csv));
    EXPECT_NE(log.meta.notes.find("at stop: " + r.at_stop), std::string::npos) << log.meta.notes;
    EXPECT_EQ(log.samples(), r.rows);
    EXPECT_EQ(log.meta.source, "twin");
    EXPECT_NE(log.meta.notes.find(std::string("stop: ") + to_string(r.reason)), std::string::npos) << log.meta.notes;
    if (log.samples() > 0) EXPECT_NEAR(log.time(log.samples() - 1), r.trajectory_time, 0.05);
  }

  twin::TwinConfig twin_;
  HardwareConfig hw_;
  control::FfpdGains gains_;
  std::filesystem::path dir_;
};

}  // namespace
}  // namespace symoro::hardware
