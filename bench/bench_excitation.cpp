// An optimized excitation design (excitation/design.hpp) of CRANE-X7's full model (8
// joints, 65 base parameters): 5 harmonics, 10 s period, 4 random starts, position, velocity,
// acceleration and CAD-torque limits (issue 29's target: a 7-DoF design in under 60 s on 2
// cores); and one evaluation of the criterion with its exact gradient.
#include <benchmark/benchmark.h>

#include <algorithm>

#include <symoro/crane_x7.hpp>

#include "symoro/excitation/design.hpp"
#include "symoro/identify/identification_model.hpp"
#include "symoro/robot/compiled_model.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/truth.hpp"

namespace {

using Model = symoro::crane_x7::Model;
using namespace symoro::identify;
using namespace symoro::excitation;

ExcitationDesignOptions crane_options(int starts) {
  const auto& joints = Model::joints;
  ExcitationDesignOptions o;
  o.harmonics = 5;
  o.period = 10;
  o.starts = starts;
  o.start = Eigen::VectorXd::Zero(Model::nq);
  o.start(3) = -1.5707963267948966;  // posture A
  o.start(7) = 0.7;
  o.limits.lower.resize(Model::nq);
  o.limits.upper.resize(Model::nq);
  o.limits.torque.resize(Model::nq);
  for (int j = 0; j < Model::nq; ++j) {
    o.limits.lower(j) = std::max(joints[j].lower, joints[j].audit_lower) + 0.035;
    o.limits.upper(j) = std::min(joints[j].upper, joints[j].audit_upper) - 0.035;
    o.limits.torque(j) = 0.8 * joints[j].effort;
  }
  o.limits.velocity = Eigen::VectorXd::Constant(Model::nq, 2.0);
  o.limits.acceleration = Eigen::VectorXd::Constant(Model::nq, 8.0);
  const auto c = symoro::twin::read_twin_config(std::string(SYMORO_ROBOTS_DIR) + "/crane_x7/twin.yaml", Model::nq, "");
  o.nominal = symoro::twin::make_truth(symoro::robot::compiled_model<Model>(), c).phi;
  return o;
}

void BM_ExcitationDesign_CraneX7Full(benchmark::State& state) {
  const auto model = identification_model<Model>();
  const ExcitationDesignOptions o = crane_options(static_cast<int>(state.range(0)));
  double criterion = 0;
  for (auto _ : state) {
    const ExcitationDesign d = design_excitation(*model, o);
    criterion = d.criterion;
    state.counters["starts_passed"] =
        static_cast<double>(std::count_if(d.starts.begin(), d.starts.end(), [](const auto& s) { return s.passed; }));
    benchmark::DoNotOptimize(criterion);
  }
  state.counters["log_det"] = criterion;
}
BENCHMARK(BM_ExcitationDesign_CraneX7Full)->Arg(4)->Unit(benchmark::kSecond)->Iterations(1);

void BM_ExcitationCriterionGradient_CraneX7Full(benchmark::State& state) {
  const auto model = identification_model<Model>();
  const ExcitationDesignOptions o = crane_options(1);
  ExcitationCriterion c(*model, FourierBasis(Model::nq, 5, 10.0, 100, o.start));
  Eigen::VectorXd x = Eigen::VectorXd::Constant(c.basis().variables(), 0.05), g;
  for (int j = 0; j < Model::nq; ++j) x.segment(j * 10, 5) << 0.1, -0.05, 0.02, -0.04, -0.03;
  c.scale_columns_at(x);
  for (auto _ : state) benchmark::DoNotOptimize(c.value(x, &g));
}
BENCHMARK(BM_ExcitationCriterionGradient_CraneX7Full)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
