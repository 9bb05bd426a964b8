// The C++ side of bench_python.py: a generated function called in a plain C++ loop over a batch
// of 10,000 states (the states rows of an Eigen matrix, as a C++ user holds them), and on one
// state. bench_python.py sets the Python binding's cost against these.
#include <random>

#include <Eigen/Core>
#include <benchmark/benchmark.h>

#include <symoro/crane_x7.hpp>
#include <symoro/planar2r.hpp>

namespace {

constexpr int kBatch = 10000;

template <class Model>
struct States {
  using Rows = Eigen::Matrix<double, Eigen::Dynamic, Model::nq, Eigen::RowMajor>;
  Rows q, qd, qdd, out;
  Eigen::Matrix<double, Model::np, 1> phi;
  explicit States(int n) : q(n, Model::nq), qd(n, Model::nq), qdd(n, Model::nq), out(n, Model::nq) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    for (Rows* m : {&q, &qd, &qdd})
      for (Eigen::Index i = 0; i < m->size(); ++i) m->data()[i] = u(rng);
    for (int i = 0; i < Model::np; ++i) phi[i] = u(rng);
  }
};

template <class Model>
void inverse_dynamics_batch(benchmark::State& state) {
  States<Model> s(kBatch);
  Eigen::Matrix<double, Model::nq, 1> tau;
  for (auto _ : state) {
    for (int k = 0; k < kBatch; ++k) {
      Model::inverse_dynamics(s.q.row(k).transpose(), s.qd.row(k).transpose(), s.qdd.row(k).transpose(), s.phi, tau);
      s.out.row(k) = tau.transpose();
    }
    benchmark::DoNotOptimize(s.out.data());
    benchmark::ClobberMemory();
  }
  state.counters["ns_per_state"] = benchmark::Counter(static_cast<double>(kBatch) * state.iterations(),
                                                      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

template <class Model>
void regressor_batch(benchmark::State& state) {
  States<Model> s(kBatch);
  Eigen::Matrix<double, Eigen::Dynamic, Model::nq * Model::np, Eigen::RowMajor> out(kBatch, Model::nq * Model::np);
  Eigen::Matrix<double, Model::nq, Model::np> w;
  for (auto _ : state) {
    for (int k = 0; k < kBatch; ++k) {
      Model::regressor(s.q.row(k).transpose(), s.qd.row(k).transpose(), s.qdd.row(k).transpose(), w);
      Eigen::Map<Eigen::Matrix<double, Model::nq, Model::np, Eigen::RowMajor>>(out.row(k).data()) = w;
    }
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.counters["ns_per_state"] = benchmark::Counter(static_cast<double>(kBatch) * state.iterations(),
                                                      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

template <class Model>
void inverse_dynamics_one(benchmark::State& state) {
  States<Model> s(1);
  Eigen::Matrix<double, Model::nq, 1> tau;
  for (auto _ : state) {
    Model::inverse_dynamics(s.q.row(0).transpose(), s.qd.row(0).transpose(), s.qdd.row(0).transpose(), s.phi, tau);
    benchmark::DoNotOptimize(tau.data());
    benchmark::ClobberMemory();
  }
}

}  // namespace

BENCHMARK_TEMPLATE(inverse_dynamics_batch, symoro::planar2r::Model)->Name("inverse_dynamics_batch/planar2r.full");
BENCHMARK_TEMPLATE(inverse_dynamics_batch, symoro::crane_x7::reduced::Model)
    ->Name("inverse_dynamics_batch/crane_x7.reduced");
BENCHMARK_TEMPLATE(regressor_batch, symoro::crane_x7::reduced::Model)->Name("regressor_batch/crane_x7.reduced");
BENCHMARK_TEMPLATE(inverse_dynamics_one, symoro::planar2r::Model)->Name("inverse_dynamics_one/planar2r.full");
BENCHMARK_TEMPLATE(inverse_dynamics_one, symoro::crane_x7::reduced::Model)
    ->Name("inverse_dynamics_one/crane_x7.reduced");
BENCHMARK_MAIN();
