// Nanoseconds per call of the generated CRANE-X7 models (the paper's 39-parameter variant and
// the full 65-parameter model), in double and in ceres::Jet<double, np>: the Jet is seeded on
// phi for tau, M and qdd (what identification differentiates), and on q for the regressor.
//
//   bench_models --benchmark_filter=reduced
//
// What the units of bench_models share: each registers one model with SYMORO_BENCH_ALL (issue 27:
// one unit for both took 57 s at -j2). Registration follows the units' link order
// (bench/CMakeLists.txt): the reduced model, then the full one.
#pragma once

#include <array>
#include <random>
#include <type_traits>

#include <Eigen/Core>
#include <benchmark/benchmark.h>
#include <ceres/jet.h>

namespace {

// Scalar tags for the benchmark names.
struct Double {};
struct Jet {};

// A few random states inside the joint limits, cycled through so that no call sees the inputs
// of the previous one (the compiler cannot hoist work out of the loop, and the branch on
// sign(qd) does not always go one way). Each also carries its Jet-seeded q and phi.
template <class Model>
struct Inputs {
  static constexpr int kCount = 16;
  using J = ceres::Jet<double, Model::np>;
  struct One {
    Eigen::Matrix<double, Model::nq, 1> q, qd, qdd, tau;
    Eigen::Matrix<double, Model::np, 1> phi;
    Eigen::Matrix<J, Model::nq, 1> q_jet;
    Eigen::Matrix<J, Model::np, 1> phi_jet;
  };
  std::array<One, kCount> states;
  std::size_t next = 0;

  Inputs() {
    std::mt19937 gen(42);
    const auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(gen); };
    for (auto& s : states) {
      for (int i = 0; i < Model::nq; ++i) {
        s.q(i) = uniform(Model::joints[i].lower, Model::joints[i].upper);
        s.qd(i) = uniform(-2, 2);
        s.qdd(i) = uniform(-3, 3);
        s.tau(i) = uniform(-2, 2);
        s.q_jet(i) = J(s.q(i), i);
      }
      // Positive base parameters of order 0.01 keep M well conditioned enough for timing.
      for (int i = 0; i < Model::np; ++i) {
        s.phi(i) = uniform(0.005, 0.02);
        s.phi_jet(i) = J(s.phi(i), i);
      }
    }
  }
  const One& operator()() { return states[next++ % kCount]; }
};

template <class Model, class S>
void regressor(benchmark::State& state) {
  Inputs<Model> in;
  if constexpr (std::is_same_v<S, Double>) {
    Eigen::Matrix<double, Model::nq, Model::np> W;
    for (auto _ : state) {
      const auto& x = in();
      Model::regressor(x.q, x.qd, x.qdd, W);
      benchmark::DoNotOptimize(W.data());
      benchmark::ClobberMemory();
    }
  } else {
    // Jet seeded on q: dW/dq. nq x np Jets exceed Eigen's fixed-size stack limit, so the
    // output is a dynamic matrix (allocated once, outside the loop).
    Eigen::Matrix<typename Inputs<Model>::J, Eigen::Dynamic, Eigen::Dynamic> W(Model::nq, Model::np);
    for (auto _ : state) {
      const auto& x = in();
      Model::regressor(x.q_jet, x.qd, x.qdd, W);
      benchmark::DoNotOptimize(W.data());
      benchmark::ClobberMemory();
    }
  }
}

template <class Model, class S>
void inverse_dynamics(benchmark::State& state) {
  Inputs<Model> in;
  using Scalar = std::conditional_t<std::is_same_v<S, Double>, double, typename Inputs<Model>::J>;
  Eigen::Matrix<Scalar, Model::nq, 1> tau;
  for (auto _ : state) {
    const auto& x = in();
    if constexpr (std::is_same_v<S, Double>)
      Model::inverse_dynamics(x.q, x.qd, x.qdd, x.phi, tau);
    else
      Model::inverse_dynamics(x.q, x.qd, x.qdd, x.phi_jet, tau);
    benchmark::DoNotOptimize(tau.data());
    benchmark::ClobberMemory();
  }
}

template <class Model, class S>
void inertia(benchmark::State& state) {
  Inputs<Model> in;
  using Scalar = std::conditional_t<std::is_same_v<S, Double>, double, typename Inputs<Model>::J>;
  Eigen::Matrix<Scalar, Model::nq, Model::nq> M;
  for (auto _ : state) {
    const auto& x = in();
    if constexpr (std::is_same_v<S, Double>)
      Model::inertia(x.q, x.phi, M);
    else
      Model::inertia(x.q, x.phi_jet, M);
    benchmark::DoNotOptimize(M.data());
    benchmark::ClobberMemory();
  }
}

template <class Model, class S>
void forward_dynamics(benchmark::State& state) {
  Inputs<Model> in;
  using Scalar = std::conditional_t<std::is_same_v<S, Double>, double, typename Inputs<Model>::J>;
  Eigen::Matrix<Scalar, Model::nq, 1> qdd;
  for (auto _ : state) {
    const auto& x = in();
    if constexpr (std::is_same_v<S, Double>)
      Model::forward_dynamics(x.q, x.qd, x.tau, x.phi, qdd);
    else
      Model::forward_dynamics(x.q, x.qd, x.tau, x.phi_jet, qdd);
    benchmark::DoNotOptimize(qdd.data());
    benchmark::ClobberMemory();
  }
}

#define SYMORO_BENCH_ALL(model)                        \
  BENCHMARK_TEMPLATE(regressor, model, Double);        \
  BENCHMARK_TEMPLATE(regressor, model, Jet);           \
  BENCHMARK_TEMPLATE(inverse_dynamics, model, Double); \
  BENCHMARK_TEMPLATE(inverse_dynamics, model, Jet);    \
  BENCHMARK_TEMPLATE(inertia, model, Double);          \
  BENCHMARK_TEMPLATE(inertia, model, Jet);             \
  BENCHMARK_TEMPLATE(forward_dynamics, model, Double); \
  BENCHMARK_TEMPLATE(forward_dynamics, model, Jet)

}  // namespace
