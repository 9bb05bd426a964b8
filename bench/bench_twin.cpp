// The digital twin's speed: simulated seconds per wall second on one core (the goal is
// at least 200), for the default configuration and for the ideal and all-effects twins.
#include <benchmark/benchmark.h>

#include <symoro/crane_x7.hpp>

#include "symoro/robot/compiled_model.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/simulator.hpp"

namespace {

using Model = symoro::crane_x7::Model;
const std::string kRobot = std::string(SYMORO_ROBOTS_DIR) + "/crane_x7";

void run(benchmark::State& state, const std::string& trajectory, int effects) {
  auto c = symoro::twin::read_twin_config(kRobot + "/twin.yaml", Model::nq);
  if (effects == 0) c.effects.disable_all();
  if (effects == 2)
    for (const auto& e : symoro::twin::Effects::names()) c.effects.set(e, true);
  const symoro::twin::ClosedLoopTwin twin(symoro::robot::compiled_model<Model>(), c);
  const auto design = symoro::trajectory::TrajectoryDesign::read(
      kRobot + "/trajectories.yaml", std::vector<symoro::JointInfo>(Model::joints.begin(), Model::joints.end()));
  const auto traj = design.build(trajectory);
  symoro::twin::RunOptions ro;
  double simulated = 0;
  for (auto _ : state) {
    ++ro.seed;
    symoro::twin::RunStats st;
    benchmark::DoNotOptimize(twin.run(traj, ro, &st));
    simulated += st.simulated;
  }
  state.counters["sim_s_per_wall_s"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
}

void BM_TwinDefault(benchmark::State& s) { run(s, "AG02", 1); }
void BM_TwinIdeal(benchmark::State& s) { run(s, "AG02", 0); }
void BM_TwinAllEffects(benchmark::State& s) { run(s, "AG02", 2); }
BENCHMARK(BM_TwinDefault)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_TwinIdeal)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_TwinAllEffects)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
