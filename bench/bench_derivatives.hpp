// Nanoseconds per call of the generated derivatives against their values and the Jet path, per
// robot model (issue 16):
//   id_value       inverse_dynamics, double
//   id_derivatives inverse_dynamics_derivatives (tau, d tau / d q, d tau / d qd), double
//   id_jet         inverse_dynamics in ceres::Jet<double, 2 nq> seeded on (q, qd): the same
//                  derivatives the way CLIE took them before
//   fd_value       forward_dynamics (ddm.txt), double
//   fd_derivatives forward_dynamics_derivatives (qdd, d qdd / d q, d qdd / d qd, M^-1,
//                  d qdd / d phi), double
//   fd_jet_path    the same four blocks the Jet way: M, h, LDLT, qdd, the Jet<2 nq> inverse
//                  dynamics, the regressor, M^-1 and the three products
//
//   m_derivatives  inertia_derivatives (M and d M / d q_k), double: the PD audit's gradients
//   m_jet          inertia in ceres::Jet<double, nq> seeded on q: the same, the way the audit
//                  took them before
//   m_second       inertia_derivatives in Jet<double, nq>: d2 M / d q2 as well (the audit's
//                  Hessians)
//
//   bench_derivatives --benchmark_filter=crane_x7
//
// The benchmarks of bench_derivatives (what its units share): each unit registers the models it
// includes with SYMORO_BENCH_MODEL, one crane_x7 model per unit (issue 27: one unit for all the
// models took 112 s at -j2). Registration follows the units' link order (bench/CMakeLists.txt).
#pragma once

#include <array>
#include <memory>
#include <random>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <benchmark/benchmark.h>
#include <ceres/jet.h>

namespace {

// Random states inside the joint limits, cycled so that no call sees the previous one's inputs;
// parameters from a physically consistent-looking draw (positive diagonal terms dominate).
template <class Model>
struct Inputs {
  static constexpr int kCount = 16;
  struct One {
    Eigen::Matrix<double, Model::nq, 1> q, qd, qdd, tau;
    Eigen::Matrix<double, Model::np, 1> phi;
  };
  std::array<One, kCount> states;
  std::size_t next = 0;

  Inputs() {
    std::mt19937 gen(7);
    const auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(gen); };
    for (auto& s : states) {
      for (int i = 0; i < Model::nq; ++i) {
        const double lo = Model::joints[i].lower, hi = Model::joints[i].upper;
        s.q(i) = hi > lo ? uniform(lo, hi) : uniform(-1, 1);
        s.qd(i) = uniform(-2, 2);
        s.qdd(i) = uniform(-3, 3);
        s.tau(i) = uniform(-2, 2);
      }
      for (int i = 0; i < Model::np; ++i) s.phi(i) = uniform(0.005, 0.02);
    }
  }
  const One& operator()() { return states[next++ % kCount]; }
};

template <class Model>
void id_value(benchmark::State& state) {
  Inputs<Model> in;
  Eigen::Matrix<double, Model::nq, 1> tau;
  for (auto _ : state) {
    const auto& x = in();
    Model::inverse_dynamics(x.q, x.qd, x.qdd, x.phi, tau);
    benchmark::DoNotOptimize(tau.data());
    benchmark::ClobberMemory();
  }
}

template <class Model>
void id_derivatives(benchmark::State& state) {
  Inputs<Model> in;
  typename Model::template InverseDynamicsDerivatives<double> d;
  for (auto _ : state) {
    const auto& x = in();
    Model::inverse_dynamics_derivatives(x.q, x.qd, x.qdd, x.phi, d);
    benchmark::DoNotOptimize(d.dq.data());
    benchmark::ClobberMemory();
  }
}

template <class Model>
void id_jet(benchmark::State& state) {
  constexpr int n = Model::nq;
  using Jet = ceres::Jet<double, 2 * n>;
  Inputs<Model> in;
  Eigen::Matrix<Jet, n, 1> q, qd, tau;
  Eigen::Matrix<double, n, 2 * n> J;
  for (auto _ : state) {
    const auto& x = in();
    for (int i = 0; i < n; ++i) {
      q(i) = Jet(x.q(i), i);
      qd(i) = Jet(x.qd(i), n + i);
    }
    Model::inverse_dynamics(q, qd, x.qdd, x.phi, tau);
    for (int j = 0; j < n; ++j) J.row(j) = tau(j).v.transpose();
    benchmark::DoNotOptimize(J.data());
    benchmark::ClobberMemory();
  }
}

template <class Model>
void fd_value(benchmark::State& state) {
  Inputs<Model> in;
  Eigen::Matrix<double, Model::nq, 1> qdd;
  for (auto _ : state) {
    const auto& x = in();
    Model::forward_dynamics(x.q, x.qd, x.tau, x.phi, qdd);
    benchmark::DoNotOptimize(qdd.data());
    benchmark::ClobberMemory();
  }
}

template <class Model>
void fd_derivatives(benchmark::State& state) {
  Inputs<Model> in;
  typename Model::template ForwardDynamicsDerivatives<double> d;
  for (auto _ : state) {
    const auto& x = in();
    benchmark::DoNotOptimize(Model::forward_dynamics_derivatives(x.q, x.qd, x.tau, x.phi, d));
    benchmark::DoNotOptimize(d.dphi.data());
    benchmark::ClobberMemory();
  }
}

template <class Model>
void fd_jet_path(benchmark::State& state) {
  constexpr int n = Model::nq, np = Model::np;
  using Mat = Eigen::Matrix<double, n, n>;
  using Vec = Eigen::Matrix<double, n, 1>;
  using Jet = ceres::Jet<double, 2 * n>;
  Inputs<Model> in;
  Eigen::Matrix<Jet, n, 1> q, qd, tau;
  Eigen::Matrix<double, n, 2 * n> J;
  Eigen::Matrix<double, n, np> W, dphi;
  Mat M, M_inv, dq, dqd;
  Vec h, qdd;
  for (auto _ : state) {
    const auto& x = in();
    Model::inertia(x.q, x.phi, M);
    Model::nonlinear_effects(x.q, x.qd, x.phi, h);
    const Eigen::LDLT<Mat> ldlt(M);
    qdd = ldlt.solve(x.tau - h);
    for (int i = 0; i < n; ++i) {
      q(i) = Jet(x.q(i), i);
      qd(i) = Jet(x.qd(i), n + i);
    }
    Model::inverse_dynamics(q, qd, qdd, x.phi, tau);
    for (int j = 0; j < n; ++j) J.row(j) = tau(j).v.transpose();
    Model::regressor(x.q, x.qd, qdd, W);
    M_inv = ldlt.solve(Mat::Identity());
    dq = -M_inv.lazyProduct(J.template leftCols<n>());
    dqd = -M_inv.lazyProduct(J.template rightCols<n>());
    dphi = -M_inv.lazyProduct(W);
    benchmark::DoNotOptimize(dphi.data());
    benchmark::DoNotOptimize(dq.data());
    benchmark::DoNotOptimize(dqd.data());
    benchmark::ClobberMemory();
  }
}

template <class Model>
void m_derivatives(benchmark::State& state) {
  Inputs<Model> in;
  typename Model::template InertiaDerivatives<double> d;
  for (auto _ : state) {
    const auto& x = in();
    Model::inertia_derivatives(x.q, x.phi, d);
    benchmark::DoNotOptimize(d.dq.data());
    benchmark::ClobberMemory();
  }
}

template <class Model>
void m_jet(benchmark::State& state) {
  constexpr int n = Model::nq;
  using Jet = ceres::Jet<double, n>;
  Inputs<Model> in;
  Eigen::Matrix<Jet, n, 1> q;
  Eigen::Matrix<Jet, Eigen::Dynamic, Eigen::Dynamic> M(n, n);
  for (auto _ : state) {
    const auto& x = in();
    for (int i = 0; i < n; ++i) q(i) = Jet(x.q(i), i);
    Model::inertia(q, x.phi, M);
    benchmark::DoNotOptimize(M.data());
    benchmark::ClobberMemory();
  }
}

template <class Model>
void m_second(benchmark::State& state) {
  constexpr int n = Model::nq;
  using Jet = ceres::Jet<double, n>;
  Inputs<Model> in;
  Eigen::Matrix<Jet, n, 1> q;
  auto d = std::make_unique<typename Model::template InertiaDerivatives<Jet>>();
  for (auto _ : state) {
    const auto& x = in();
    for (int i = 0; i < n; ++i) q(i) = Jet(x.q(i), i);
    Model::inertia_derivatives(q, x.phi, *d);
    benchmark::DoNotOptimize(d->dq.data());
    benchmark::ClobberMemory();
  }
}

#define SYMORO_BENCH_MODEL(label, M)                                    \
  BENCHMARK_TEMPLATE(m_derivatives, M)->Name(label "/m_derivatives");   \
  BENCHMARK_TEMPLATE(m_jet, M)->Name(label "/m_jet");                   \
  BENCHMARK_TEMPLATE(m_second, M)->Name(label "/m_second");             \
  BENCHMARK_TEMPLATE(id_value, M)->Name(label "/id_value");             \
  BENCHMARK_TEMPLATE(id_derivatives, M)->Name(label "/id_derivatives"); \
  BENCHMARK_TEMPLATE(id_jet, M)->Name(label "/id_jet");                 \
  BENCHMARK_TEMPLATE(fd_value, M)->Name(label "/fd_value");             \
  BENCHMARK_TEMPLATE(fd_derivatives, M)->Name(label "/fd_derivatives"); \
  BENCHMARK_TEMPLATE(fd_jet_path, M)->Name(label "/fd_jet_path");

}  // namespace
