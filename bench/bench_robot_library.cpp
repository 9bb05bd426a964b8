// The cost of a call through a loaded robot library (symoro/robot_abi.h) against the same
// generated function inlined, for the CRANE-X7's reduced model (8 joints, 39 parameters) and the
// RX-90's (6 joints): issue 40's target is at most 5 ns more per call. The library is built into
// the build tree's robot cache on first run (SYMORO_BENCH_ROBOT_CACHE).
#include <benchmark/benchmark.h>

#include <random>

#include "symoro/crane_x7/reduced/all.hpp"
#include "symoro/robot/load_robot.hpp"
#include "symoro/rx90.hpp"

namespace {

symoro::robot::ModelHandle handle(const char* robot, const char* model) {
  symoro::robot::LoadOptions o;
  o.cache_dir = SYMORO_BENCH_ROBOT_CACHE;
  return symoro::robot::load_robot(std::string(SYMORO_ROBOTS_DIR) + "/" + robot, o)->model(model);
}

template <class Model>
struct State {
  Eigen::Matrix<double, Model::nq, 1> q, qd, qdd, tau;
  Eigen::Matrix<double, Model::np, 1> phi;
  // The inputs may have changed, for the compiler: nothing of the call is hoisted out of the loop.
  void touch() {
    benchmark::DoNotOptimize(q);
    benchmark::DoNotOptimize(qd);
    benchmark::DoNotOptimize(qdd);
    benchmark::DoNotOptimize(phi);
  }
  State() {
    std::mt19937 g(1);
    std::uniform_real_distribution<double> u(-1, 1);
    for (auto* v : {&q, &qd, &qdd})
      for (int i = 0; i < Model::nq; ++i) (*v)(i) = u(g);
    for (int i = 0; i < Model::np; ++i) phi(i) = u(g);
  }
};

template <class Model>
void InverseDynamicsInline(benchmark::State& state) {
  State<Model> s;
  for (auto _ : state) {
    s.touch();
    Model::inverse_dynamics(s.q, s.qd, s.qdd, s.phi, s.tau);
    benchmark::DoNotOptimize(s.tau.data());
    benchmark::ClobberMemory();
  }
}
template <class Model>
void InverseDynamicsLoaded(benchmark::State& state, const char* robot, const char* model) {
  const auto h = handle(robot, model);
  State<Model> s;
  for (auto _ : state) {
    s.touch();
    h.inverse_dynamics(s.q.data(), s.qd.data(), s.qdd.data(), s.phi.data(), s.tau.data());
    benchmark::DoNotOptimize(s.tau.data());
    benchmark::ClobberMemory();
  }
}
template <class Model>
void RegressorInline(benchmark::State& state) {
  State<Model> s;
  Eigen::Matrix<double, Model::nq, Model::np> W;
  for (auto _ : state) {
    s.touch();
    Model::regressor(s.q, s.qd, s.qdd, W);
    benchmark::DoNotOptimize(W.data());
    benchmark::ClobberMemory();
  }
}
template <class Model>
void RegressorLoaded(benchmark::State& state, const char* robot, const char* model) {
  const auto h = handle(robot, model);
  State<Model> s;
  Eigen::Matrix<double, Model::nq, Model::np> W;
  for (auto _ : state) {
    s.touch();
    h.regressor(s.q.data(), s.qd.data(), s.qdd.data(), W.data());
    benchmark::DoNotOptimize(W.data());
    benchmark::ClobberMemory();
  }
}
template <class Model>
void InertiaInline(benchmark::State& state) {
  State<Model> s;
  Eigen::Matrix<double, Model::nq, Model::nq> M;
  for (auto _ : state) {
    s.touch();
    Model::inertia(s.q, s.phi, M);
    benchmark::DoNotOptimize(M.data());
    benchmark::ClobberMemory();
  }
}
template <class Model>
void InertiaLoaded(benchmark::State& state, const char* robot, const char* model) {
  const auto h = handle(robot, model);
  State<Model> s;
  Eigen::Matrix<double, Model::nq, Model::nq> M;
  for (auto _ : state) {
    s.touch();
    h.inertia(s.q.data(), s.phi.data(), M.data());
    benchmark::DoNotOptimize(M.data());
    benchmark::ClobberMemory();
  }
}

using Crane = symoro::crane_x7::reduced::Model;
using Rx90 = symoro::rx90::Model;
// Registered in pairs, inline then loaded, so the table reads as the comparison.
const bool registered = [] {
  benchmark::RegisterBenchmark("crane_x7.reduced/inverse_dynamics/inline", InverseDynamicsInline<Crane>);
  benchmark::RegisterBenchmark("crane_x7.reduced/inverse_dynamics/loaded", InverseDynamicsLoaded<Crane>, "crane_x7",
                               "reduced");
  benchmark::RegisterBenchmark("crane_x7.reduced/regressor/inline", RegressorInline<Crane>);
  benchmark::RegisterBenchmark("crane_x7.reduced/regressor/loaded", RegressorLoaded<Crane>, "crane_x7", "reduced");
  benchmark::RegisterBenchmark("crane_x7.reduced/inertia/inline", InertiaInline<Crane>);
  benchmark::RegisterBenchmark("crane_x7.reduced/inertia/loaded", InertiaLoaded<Crane>, "crane_x7", "reduced");
  benchmark::RegisterBenchmark("rx90/inverse_dynamics/inline", InverseDynamicsInline<Rx90>);
  benchmark::RegisterBenchmark("rx90/inverse_dynamics/loaded", InverseDynamicsLoaded<Rx90>, "rx90", "full");
  benchmark::RegisterBenchmark("rx90/regressor/inline", RegressorInline<Rx90>);
  benchmark::RegisterBenchmark("rx90/regressor/loaded", RegressorLoaded<Rx90>, "rx90", "full");
  return true;
}();

}  // namespace
