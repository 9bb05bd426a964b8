// The 1 kHz control loop's real-time behaviour on the steady clock, the arm's clock: the loop
// over a pseudo-terminal against the emulated CRANE-X7 servos driving the ideal twin (the rig of
// tests/runtime/hardware_rig.hpp, whose tests run on a stepped clock so that a loaded machine
// cannot change their verdicts). Counters, per run of 3 s of AG02: the period's mean and
// standard deviation, the largest jitter, the wake-up latency, overruns, skipped deadlines and
// failed sync reads (their share of cycles). Run it on an idle machine, with SCHED_FIFO allowed
// (as root or with CAP_SYS_NICE), as the arm's computer runs the loop.
#include <benchmark/benchmark.h>

#include <symoro/crane_x7.hpp>

#include <filesystem>
#include <memory>
#include <string>
#include <unistd.h>

#include "symoro/dynamixel/bus.hpp"
#include "symoro/dynamixel/serial_port.hpp"
#include "symoro/dynamixel/virtual_bus.hpp"
#include "symoro/hardware/config.hpp"
#include "symoro/hardware/controller.hpp"
#include "symoro/robot/compiled_model.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/simulator.hpp"
#include "symoro/twin_bus/twin_servo_backend.hpp"

namespace {

using Model = symoro::crane_x7::Model;
namespace hw = symoro::hardware;
const std::filesystem::path kRobot = std::filesystem::path(SYMORO_ROBOTS_DIR) / "crane_x7";

void BM_ControlLoopOverThePty(benchmark::State& state) {
  const std::vector<symoro::JointInfo> joints(Model::joints.begin(), Model::joints.end());
  symoro::twin::TwinConfig twin = symoro::twin::read_twin_config(kRobot / "twin.yaml", Model::nq);
  twin.effects.disable_all();
  hw::HardwareConfig config = hw::read_hardware_config(kRobot / "hardware.yaml", joints);
  config.safety.hold_time = 0.2;
  const symoro::control::FfpdGains gains = symoro::twin::controller_gains(twin);
  const symoro::trajectory::Trajectory traj =
      symoro::trajectory::TrajectoryDesign::read(kRobot / "trajectories.yaml", joints).build("AG02");
  const std::string csv =
      (std::filesystem::temp_directory_path() / ("bench_control_loop_" + std::to_string(::getpid()) + ".csv")).string();
  hw::ControlOptions o;
  o.seconds = 3.0;
  o.robot = "crane_x7";
  o.source = "twin";
  o.verbose = false;
  o.watchdog_cycles = 20;
  o.realtime_priority = 21;
  hw::TimingStats sum;
  double period_sq = 0, cycles = 0;
  int runs = 0;
  for (auto _ : state) {
    state.PauseTiming();
    Eigen::VectorXd q0(Model::nq), qd(Model::nq), qdd(Model::nq);
    traj.evaluate(0, q0, qd, qdd);
    symoro::dynamixel::VirtualBus virt(
        symoro::twin_bus::virtual_servos(config),
        std::make_unique<symoro::twin_bus::TwinServoBackend>(symoro::robot::compiled_model<Model>(), twin, config, q0));
    symoro::dynamixel::SerialPort port(virt.device(), config.baud);
    symoro::dynamixel::Bus bus(port);
    state.ResumeTiming();
    const hw::ControlResult r = hw::run_control(bus, config, joints, gains, traj, csv, o);
    if (r.reason != hw::StopReason::completed) state.SkipWithError(r.message.c_str());
    const hw::TimingStats& t = r.timing;
    sum.period_mean += t.period_mean * t.cycles;
    period_sq += (t.period_std * t.period_std + t.period_mean * t.period_mean) * t.cycles;
    cycles += t.cycles;
    sum.jitter_max = std::max(sum.jitter_max, t.jitter_max);
    sum.latency_max = std::max(sum.latency_max, t.latency_max);
    sum.latency_mean += t.latency_mean * t.cycles;
    sum.overruns += t.overruns;
    sum.skipped += t.skipped;
    sum.read_failures += t.read_failures;
    ++runs;
  }
  std::filesystem::remove(csv);
  std::filesystem::remove(csv + ".yaml");
  if (cycles > 0) {
    const double mean = sum.period_mean / cycles;
    state.counters["period_mean_us"] = mean * 1e6;
    state.counters["period_std_us"] = std::sqrt(std::max(0.0, period_sq / cycles - mean * mean)) * 1e6;
    state.counters["jitter_max_us"] = sum.jitter_max * 1e6;
    state.counters["latency_mean_us"] = sum.latency_mean / cycles * 1e6;
    state.counters["latency_max_us"] = sum.latency_max * 1e6;
    state.counters["overruns_per_1000"] = 1000.0 * sum.overruns / cycles;
    state.counters["skipped_per_1000"] = 1000.0 * sum.skipped / cycles;
    state.counters["failed_reads_per_1000"] = 1000.0 * sum.read_failures / cycles;
  }
}
BENCHMARK(BM_ControlLoopOverThePty)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(3);

}  // namespace
