// CLIE's cost: the closed-loop simulation in simulated seconds per wall second, with and
// without forward sensitivities (the paper's 39-parameter model on AG02; the sensitivities'
// derivatives generated, once per Heun step at its midpoint by default, at both stages (the exact
// derivative of the discrete map) in the *Exact benchmarks), and one complete
// CLIE refinement of AG02 at 40 ms on data from the default twin, from the truth perturbed by
// 20 % (alternating signs).
//
// The *ThroughInterface benchmarks make the same calls through identify::ClosedLoop, the virtual
// interface the study is compiled against; the *Runtime ones run what the study actually runs, the
// one simulator over a model handle (identification_model<Reduced>(): dynamic sizes, the same bits).
//
//   bench_clie --benchmark_filter=Simulate
#include <memory>

#include <benchmark/benchmark.h>

#include <symoro/crane_x7.hpp>

#include "symoro/identify/clie.hpp"
#include "symoro/identify/detail/clie_model.hpp"
#include "symoro/identify/detail/closed_loop_model.hpp"
#include "symoro/identify/identification_model.hpp"
#include "symoro/robot/compiled_model.hpp"
#include "symoro/trajectory/sampled_reference.hpp"
#include "symoro/preprocess/preprocess.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/simulator.hpp"

namespace {

using Full = symoro::crane_x7::Model;
using Reduced = symoro::crane_x7::reduced::Model;
namespace identify = symoro::identify;
const std::string kRobot = std::string(SYMORO_ROBOTS_DIR) + "/crane_x7";

struct Fixture {
  symoro::twin::TwinConfig config = symoro::twin::read_twin_config(kRobot + "/twin.yaml", Full::nq);
  symoro::trajectory::Trajectory trajectory =
      symoro::trajectory::TrajectoryDesign::read(
          kRobot + "/trajectories.yaml", std::vector<symoro::JointInfo>(Full::joints.begin(), Full::joints.end()))
          .build("AG02");
  Eigen::VectorXd truth =
      Reduced::from_parent(symoro::twin::make_truth(symoro::robot::compiled_model<Full>(), config).phi);
  identify::ClosedLoopSimulator<Reduced> sim{identify::closed_loop_setup(config.controller), trajectory};
  // The exact derivatives of the discrete map (ClosedLoopSetup::exact_sensitivities).
  identify::ClosedLoopSimulator<Reduced> sim_exact{exact_setup(config), trajectory};
  // What the runtime simulates (identification_model<Reduced>(): the one implementation over the
  // model's handle, in dynamic sizes; bit for bit the fixed-size simulator's numbers).
  std::unique_ptr<identify::ClosedLoop> runtime = identify::identification_model<Reduced>()->closed_loop(
      identify::closed_loop_setup(config.controller),
      symoro::trajectory::sample(trajectory, identify::closed_loop_setup(config.controller).gains.period));

  static identify::ClosedLoopSetup exact_setup(const symoro::twin::TwinConfig& c) {
    identify::ClosedLoopSetup s = identify::closed_loop_setup(c.controller);
    s.exact_sensitivities = true;
    return s;
  }
};

const Fixture& fixture() {
  static const Fixture f;
  return f;
}

enum class Path { fast, exact };

const identify::ClosedLoopSimulator<Reduced>& simulator(const Fixture& f, Path p) {
  return p == Path::exact ? f.sim_exact : f.sim;
}

void simulate(benchmark::State& state, bool sensitivities, Path path = Path::fast, bool interface = false) {
  const Fixture& f = fixture();
  // Through the model-independent interface (a virtual call, as CLIE and the study make it) or
  // on the concrete ClosedLoopSimulator<Reduced> (resolved at compile time).
  const identify::ClosedLoop& through = simulator(f, path);
  const auto& sim = simulator(f, path);
  symoro::preprocess::Channels tau, dtau;
  double simulated = 0;
  for (auto _ : state) {
    const bool ok = interface ? through.simulate(f.truth, tau, sensitivities ? &dtau : nullptr, nullptr)
                              : sim.simulate(f.truth, tau, sensitivities ? &dtau : nullptr, nullptr);
    if (!ok) state.SkipWithError("diverged");
    simulated += (sim.cycles() - 1) * sim.period();
  }
  state.counters["sim_s_per_wall_s"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
}

void BM_Simulate(benchmark::State& s) { simulate(s, false); }
void BM_SimulateWithSensitivities(benchmark::State& s) { simulate(s, true); }
BENCHMARK(BM_Simulate)->Unit(benchmark::kMillisecond)->UseRealTime();
// The same through identify::ClosedLoop (issue 27: the interface must cost no measurable time).
void BM_SimulateThroughInterface(benchmark::State& s) { simulate(s, false, Path::fast, true); }
void BM_SimulateWithSensitivitiesThroughInterface(benchmark::State& s) { simulate(s, true, Path::fast, true); }
BENCHMARK(BM_SimulateThroughInterface)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SimulateWithSensitivitiesThroughInterface)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
void BM_SimulateWithSensitivitiesExact(benchmark::State& s) { simulate(s, true, Path::exact); }
BENCHMARK(BM_SimulateWithSensitivities)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_SimulateWithSensitivitiesExact)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

// The runtime's simulation (Fixture::runtime), what dynid and Python run.
void simulate_runtime(benchmark::State& state, bool sensitivities) {
  const Fixture& f = fixture();
  symoro::preprocess::Channels tau, dtau;
  double simulated = 0;
  for (auto _ : state) {
    if (!f.runtime->simulate(f.truth, tau, sensitivities ? &dtau : nullptr, nullptr)) state.SkipWithError("diverged");
    simulated += (f.runtime->cycles() - 1) * f.runtime->period();
  }
  state.counters["sim_s_per_wall_s"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
}
void BM_SimulateRuntime(benchmark::State& s) { simulate_runtime(s, false); }
void BM_SimulateWithSensitivitiesRuntime(benchmark::State& s) { simulate_runtime(s, true); }
BENCHMARK(BM_SimulateRuntime)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_SimulateWithSensitivitiesRuntime)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

void clie_ag02(benchmark::State& state, Path path, bool runtime = false) {
  const Fixture& f = fixture();
  symoro::twin::RunOptions run;
  run.robot = "crane_x7";
  const symoro::io::Log log =
      symoro::twin::ClosedLoopTwin(symoro::robot::compiled_model<Full>(), f.config).run(f.trajectory, run);
  identify::ClieOptions options;
  const symoro::preprocess::Samples samples = symoro::preprocess::preprocess(log, 0.04, options.preprocess);
  Eigen::VectorXd phi0 = f.truth;
  for (int i = 0; i < phi0.size(); ++i) phi0(i) *= i % 2 ? 1.2 : 0.8;
  identify::ClieResult r;
  for (auto _ : state) {
    r = runtime ? identify::clie(*f.runtime, samples, phi0, options)
                : identify::clie<Reduced>(simulator(f, path), samples, phi0, options);
    if (!r.success) state.SkipWithError(r.termination.c_str());
  }
  state.counters["iterations"] = r.iterations;
  state.counters["jacobians"] = r.jacobian_evaluations;
  state.counters["residuals"] = r.residual_evaluations;
  state.counters["cost_initial"] = r.initial_cost;
  state.counters["cost_final"] = r.final_cost;
  state.counters["rms_final_max"] = r.rms_final.size() ? r.rms_final.maxCoeff() : 0.0;
  state.counters["at_bound"] = static_cast<double>(r.at_bound.size());
  state.counters["wall_s"] = r.wall;
  state.SetLabel(r.termination.substr(0, 60));
}
void BM_ClieAG02At40ms(benchmark::State& s) { clie_ag02(s, Path::fast); }
void BM_ClieAG02At40msExact(benchmark::State& s) { clie_ag02(s, Path::exact); }
BENCHMARK(BM_ClieAG02At40ms)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);
BENCHMARK(BM_ClieAG02At40msExact)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);
void BM_ClieAG02At40msRuntime(benchmark::State& s) { clie_ag02(s, Path::fast, true); }
BENCHMARK(BM_ClieAG02At40msRuntime)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

}  // namespace
