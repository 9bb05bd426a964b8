// ClosedLoopSimulator<Model> (interface and timing in closed_loop.hpp): the identified model's
// forward dynamics under the FF+PD controller, with forward sensitivities d x / d phi: by
// default a second-order accurate linearization, optionally the exact derivatives of the
// discrete simulation (ClosedLoopSetup::exact_sensitivities).
//
// Integration: Heun's explicit trapezoidal rule while a command is held,
//   k1 = f(x0), k2 = f(x0 + h k1), x1 = x0 + h/2 (k1 + k2),  f(q, qd) = (qd, M^-1 (u - h(q, qd))).
// The sensitivities S = d(q, qd)/d phi go through the same two stages, each differentiating
// M(q) qdd + h(q, qd) = u:  d qdd = M^-1 (d u - J_q d q - J_qd d qd - W(q, qd, qdd)), taken from
// the generated forward_dynamics_derivatives (d qdd / d q = -M^-1 J_q, d qdd / d qd = -M^-1 J_qd,
// d qdd / d tau = M^-1, d qdd / d phi = -M^-1 W, in one call that shares M's factorization and
// every subexpression). (A Jet over (q, qd) through the inverse dynamics gave the same to
// round-off at five times the cost; it was dropped with the compile time it cost every model.)
//
// Exact sensitivities need those derivatives at both stages. By default they are taken once per
// step, at its midpoint x0 + h/2 f(x0), and serve both stages (x itself goes through the plain
// forward dynamics, so tau is the plain simulation's bit for bit): S then solves the
// linearization frozen over the step, O(h^2) from the exact derivative like Heun itself, no
// longer the derivative of the discrete map. Measured (V01 excerpt, reduced model, test_identify_clie):
// d tau off the exact by 6e-5 of each parameter's largest entry, central differences of the
// simulation by 1.5e-5 (exact: 6e-7); the stage-1 Jacobians for both stages lag by h/2 and were
// 3e-2 off. Per step: one derivative call and two plain forward dynamics instead of two derivative
// calls (AG02: 0.92 s instead of 1.23 s with sensitivities, bench_clie).
//
// Where the steps lie (ClosedLoopSetup::split_at_sampling): a command is held from t_k + delay
// to t_{k+1} + delay, and the plant is smooth over that whole hold, so by default one hold is
// integrated in `substeps` steps and q(t_{k+1}) is read off the step that contains the sampling
// instant: Heun's q update is q0 + s qd0 + s^2/2 qdd0 for a step of length s, so that reading is
// exactly the q a step ending at t_{k+1} would give, at half the stage evaluations of splitting
// the hold there. split_at_sampling = true ends steps at every t_k instead, as the twin does.
// Measured (PA03, reduced model at the twin's truth, against 32 split substeps): one step per
// hold is off by 6e-7 N m rms (8e-6 max) in tau and 8e-6 relative in d tau; splitting gives
// 4e-7 N m for twice the work. Both are far below the servos' current LSB (6 mN m), so Heun
// with one step per hold is the default; RK4 would double the work again for nothing visible.
//
// sign(qd) (Coulomb friction, FS in a full model) differentiates to 0: d tau / d FS is exact
// for the discrete map only while no step straddles a velocity reversal.
#pragma once

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/control/ffpd.hpp"
#include "symoro/identify/closed_loop.hpp"
#include "symoro/preprocess/channels.hpp"
#include "symoro/trajectory/trajectory.hpp"

namespace symoro::identify {

namespace detail {

// Divergence reports (closed_loop.cpp).
Divergence tracking_divergence(double time, int joint, double error);
Divergence indefinite_inertia(double time, double smallest_pivot);
Divergence not_finite(double time);
// Throws std::invalid_argument when a setup cannot be simulated.
void check_setup(const ClosedLoopSetup& setup, int joints);

// dst += scale a b (column-major, a n x n, b n x c): for each of b's entries in column order,
// dst's column j += a's column k times (scale b(k, j)). Element-wise operations only, in one
// order, so the fixed-size simulator below and the dynamic-size one (loaded_closed_loop.cpp)
// give the same bits: Eigen's lazy products reduce their inner sums in an order that depends on
// the sizes (their sensitivities differed by 2e-13). Contiguous inner loops: they vectorize.
template <int N, class Dst, class A, class B>
inline void add_product_n(Dst& dst, const A& a, const B& b, double scale) {
  using Column = Eigen::Matrix<double, N, 1>;
  const Eigen::Index c = b.cols();
  const double* a0 = a.data();
  const Eigen::Index as = a.outerStride();
  for (Eigen::Index j = 0; j < c; ++j) {
    Eigen::Map<Column> d(dst.data() + j * dst.outerStride());
    Column acc = d;  // d's column + its terms in k order, element by element, as written above
    for (int k = 0; k < N; ++k) acc += Eigen::Map<const Column>(a0 + k * as) * (scale * b(k, j));
    d = acc;
  }
}
// a is n x n (the state's Jacobians): at a compile-time size the loops unroll (the runtime's
// simulator takes 2 to 8 joints at compile-time sizes, loaded_closed_loop.cpp); the arithmetic is
// the same either way.
template <class Dst, class A, class B>
inline void add_product(Dst& dst, const A& a, const B& b, double scale = 1.0) {
  if constexpr (A::RowsAtCompileTime != Eigen::Dynamic) {
    add_product_n<A::RowsAtCompileTime>(dst, a, b, scale);
  } else {
    const Eigen::Index n = a.rows(), c = b.cols();
    for (Eigen::Index j = 0; j < c; ++j) {
      double* d = dst.data() + j * dst.outerStride();
      for (Eigen::Index k = 0; k < n; ++k) {
        const double f = scale * b(k, j);
        const double* ak = a.data() + k * a.outerStride();
        for (Eigen::Index i = 0; i < n; ++i) d[i] += ak[i] * f;
      }
    }
  }
}

// Solves M x = b for a symmetric M (column-major n x n, its lower triangle read) by an unpivoted
// LDL^T in plain loops, with L (n x n) and D (n) the caller's scratch; returns the smallest pivot,
// x set only when every pivot is > 0 (M positive definite). Plain loops in one order, for the
// same reason as add_product: Eigen's LDLT runs its products through size-dependent kernels (the
// fixed- and dynamic-size simulations differed by 1e-13 in tau).
inline double solve_spd(int n, const double* M, const double* b, double* x, double* L, double* D) {
  double min_pivot = 0;
  for (int j = 0; j < n; ++j) {
    double d = M[j + j * n];
    for (int k = 0; k < j; ++k) d -= L[j + k * n] * L[j + k * n] * D[k];
    if (j == 0 || d < min_pivot) min_pivot = d;
    if (!(d > 0)) return min_pivot;
    D[j] = d;
    for (int i = j + 1; i < n; ++i) {
      double s = M[i + j * n];
      for (int k = 0; k < j; ++k) s -= L[i + k * n] * L[j + k * n] * D[k];
      L[i + j * n] = s / d;
    }
  }
  for (int i = 0; i < n; ++i) {  // L y = b
    double s = b[i];
    for (int k = 0; k < i; ++k) s -= L[i + k * n] * x[k];
    x[i] = s;
  }
  for (int i = 0; i < n; ++i) x[i] /= D[i];
  for (int i = n - 1; i >= 0; --i) {  // L^T x = D^-1 y
    double s = x[i];
    for (int k = i + 1; k < n; ++k) s -= L[k + i * n] * x[k];
    x[i] = s;
  }
  return min_pivot;
}

// FfpdController's law, written out so that the closed loop can carry its derivative along phi
// (the gains are constants; only q depends on phi):
//   d qd_hat_k = a d qd_hat_{k-1} + b (d q_k - d q_{k-1}),   d u = -M_hat (K_P d q + K_V d qd_hat).
// n and np may be Eigen::Dynamic (the runtime's simulator: np always): sized from the gains and
// `params` then.
template <int n, int np>
class FfpdSensitivity {
 public:
  using Vec = Eigen::Matrix<double, n, 1>;
  using SensQ = Eigen::Matrix<double, n, np>;

  explicit FfpdSensitivity(const control::FfpdGains& g, Eigen::Index params = np)
      : inertia_(g.inertia), damping_(g.damping), kp_(g.kp), kv_(g.kv) {
    const Eigen::Index joints = g.inertia.size();
    q_prev_.resize(joints);
    qd_hat_.resize(joints);
    dq_prev_.resize(joints, params);
    dqd_hat_.resize(joints, params);
    // The same expressions as FfpdController, so the two agree to the last bit.
    const double T = g.period, Tf = g.pseudo_derivative_time;
    a_ = (2 * Tf - T) / (2 * Tf + T);
    b_ = 2 / (2 * Tf + T);
    position_gain_ = inertia_.cwiseProduct(kp_);
    velocity_gain_ = inertia_.cwiseProduct(kv_);
  }

  // At rest at q (qd_hat = 0), q not depending on phi.
  template <bool Sens>
  void reset(const Vec& q) {
    q_prev_ = q;
    qd_hat_.setZero();
    if constexpr (Sens) {
      dq_prev_.setZero();
      dqd_hat_.setZero();
    }
  }

  // q_ref, qd_ref, qdd_ref: this cycle's reference (any column expression).
  template <bool Sens, class Ref>
  void update(const Vec& q, const SensQ& dq, const Ref& q_ref, const Ref& qd_ref, const Ref& qdd_ref, Vec& u,
              SensQ& du) {
    qd_hat_ = a_ * qd_hat_ + b_ * (q - q_prev_);
    q_prev_ = q;
    u = inertia_.cwiseProduct(kv_.cwiseProduct(qd_ref - qd_hat_) + kp_.cwiseProduct(q_ref - q) + qdd_ref) +
        damping_.cwiseProduct(qd_ref);
    if constexpr (Sens) {
      dqd_hat_ = a_ * dqd_hat_ + b_ * (dq - dq_prev_);
      dq_prev_ = dq;
      du.noalias() = -(position_gain_.asDiagonal() * dq);
      du.noalias() -= velocity_gain_.asDiagonal() * dqd_hat_;
    }
  }

  const Vec& velocity() const { return qd_hat_; }

 private:
  Vec inertia_, damping_, kp_, kv_, position_gain_, velocity_gain_;
  double a_ = 0, b_ = 0;
  Vec q_prev_, qd_hat_;
  SensQ dq_prev_, dqd_hat_;
};

}  // namespace detail

template <class Model>
class ClosedLoopSimulator final : public ClosedLoop {
 public:
  static constexpr int n = Model::nq;
  static constexpr int np = Model::np;
  using Vec = Eigen::Matrix<double, n, 1>;
  using Phi = Eigen::Matrix<double, np, 1>;
  using SensQ = Eigen::Matrix<double, n, np>;      // d (an n-vector) / d phi
  using SensX = Eigen::Matrix<double, 2 * n, np>;  // d (q, qd) / d phi, q rows first

  ClosedLoopSimulator(ClosedLoopSetup setup, const trajectory::Trajectory& reference)
      : ClosedLoopSimulator(setup, trajectory::sample(reference, setup.gains.period)) {}

  // References per cycle (a designed trajectory's, or a log's reference columns).
  ClosedLoopSimulator(ClosedLoopSetup setup, const trajectory::SampledReference& reference) : setup_(std::move(setup)) {
    detail::check_setup(setup_, n);
    if (reference.q.rows() != n)
      throw std::invalid_argument("closed-loop simulation: the reference " + reference.name + " has " +
                                  std::to_string(reference.q.rows()) + " joints, the model " + std::to_string(n));
    if (!(std::abs(reference.period - period()) <= 1e-9 * period()))
      throw std::invalid_argument("closed-loop simulation: the reference " + reference.name + " is sampled every " +
                                  std::to_string(reference.period) + " s, the controller runs every " +
                                  std::to_string(period()) + " s");
    cycles_ = static_cast<int>(reference.q.cols());
    pre_cycles_ = static_cast<int>(std::llround(setup_.pre_roll / period()));
    q_ref_ = reference.q;
    qd_ref_ = reference.qd;
    qdd_ref_ = reference.qdd;
  }

  int joints() const override { return n; }
  const std::vector<ParameterInfo>& parameter_info() const override {
    static const std::vector<ParameterInfo> info(Model::parameters.begin(), Model::parameters.end());
    return info;
  }
  int cycles() const override { return cycles_; }
  const ClosedLoopSetup& setup() const override { return setup_; }

  // tau: cycles() x nq, row k = the torque recorded at cycle k. With dtau (not null):
  // cycles() x (nq * np), column j * np + i = d tau_j / d phi_i. Returns false (and fills *why
  // when given) when the simulation diverges; tau is then unusable.
  bool simulate(const Eigen::VectorXd& phi, preprocess::Channels& tau, preprocess::Channels* dtau,
                Divergence* why) const {
    return simulate(phi, tau, dtau, why, nullptr);
  }
  // The same, also giving the sampled q (cycles() x nq, row k = q(t_k), what the controller saw).
  bool simulate(const Eigen::VectorXd& phi, preprocess::Channels& tau, preprocess::Channels* dtau, Divergence* why,
                preprocess::Channels* q) const override {
    if (!dtau) return simulate_into(phi, tau, nullptr, why, q);
    // Rows into the matrix.
    struct Store final : SensitivityRows {
      preprocess::Channels& m;
      Eigen::Index k = 0;
      explicit Store(preprocess::Channels& out) : m(out) {}
      void row(const double* d) override { m.row(k++) = Eigen::Map<const Eigen::RowVectorXd>(d, m.cols()); }
    } store(*dtau);
    dtau->resize(cycles_, n * np);
    return simulate_into(phi, tau, &store, why, q);
  }
  bool simulate(const Eigen::VectorXd& phi, preprocess::Channels& tau, SensitivityRows& dtau,
                Divergence* why) const override {
    return simulate_into(phi, tau, &dtau, why, nullptr);
  }

 private:
  bool simulate_into(const Eigen::VectorXd& phi, preprocess::Channels& tau, SensitivityRows* dtau, Divergence* why,
                     preprocess::Channels* q) const {
    if (phi.size() != np)
      throw std::invalid_argument("closed-loop simulation: phi has " + std::to_string(phi.size()) +
                                  " entries, the model " + std::to_string(np));
    Divergence stop;
    const Phi p = phi;
    const bool ok = dtau ? run<true>(p, tau, dtau, q, stop) : run<false>(p, tau, nullptr, q, stop);
    if (why) *why = ok ? Divergence{} : stop;
    return ok;
  }

  using Mat = Eigen::Matrix<double, n, n>;

  struct State {
    Vec q, qd;
    SensX S;  // used only with sensitivities
  };

  // qdd = M^-1 (u - h) at x, and with Sens its derivative d qdd / d phi. False on divergence.
  template <bool Sens>
  bool acceleration(const Phi& phi, const State& x, const Vec& u, const SensQ& du, double t, Vec& qdd, SensQ& dqdd,
                    Divergence& why) const {
    if (!x.q.allFinite() || !x.qd.allFinite()) {
      why = detail::not_finite(t);
      return false;
    }
    if constexpr (Sens) {
      typename Model::template ForwardDynamicsDerivatives<double> d;
      if (!Model::forward_dynamics_derivatives(x.q, x.qd, u, phi, d)) {
        why = detail::indefinite_inertia(t, d.min_pivot);
        return false;
      }
      qdd = d.qdd;
      if (!qdd.allFinite()) {
        why = detail::not_finite(t);
        return false;
      }
      // Coefficient-wise products: at these fixed sizes they beat Eigen's blocked GEMM.
      dqdd = d.dphi;
      detail::add_product(dqdd, d.dq, x.S.template topRows<n>());
      detail::add_product(dqdd, d.dqd, x.S.template bottomRows<n>());
      detail::add_product(dqdd, d.dtau, du);
      return true;
    } else {
      Mat M, L;
      Model::inertia(x.q, phi, M);
      Vec h, D;
      Model::nonlinear_effects(x.q, x.qd, phi, h);
      const Vec rhs = u - h;
      const double pivot = detail::solve_spd(n, M.data(), rhs.data(), qdd.data(), L.data(), D.data());
      if (!(pivot > 0)) {
        why = detail::indefinite_inertia(t, pivot);
        return false;
      }
      if (!qdd.allFinite()) {
        why = detail::not_finite(t);
        return false;
      }
      return true;
    }
  }

  // Holds the command u for `length` seconds from x (starting at time t0) in `substeps` Heun
  // steps. When 0 <= sample_at <= length, q (and d q) at that offset go to qs (dqs).
  template <bool Sens>
  bool hold(const Phi& phi, State& x, const Vec& u, const SensQ& du, double length, double t0, double sample_at,
            Vec& qs, SensQ& dqs, Divergence& why) const {
    if (!(length > 0)) return true;
    if constexpr (Sens)
      if (!setup_.exact_sensitivities) return hold_frozen(phi, x, u, du, length, t0, sample_at, qs, dqs, why);
    const int m = setup_.substeps;
    const double h = length / m;
    Vec qdd1, qdd2;
    SensQ dqdd1, dqdd2;
    State mid;
    for (int s = 0; s < m; ++s) {
      const double ts = t0 + s * h;
      if (!acceleration<Sens>(phi, x, u, du, ts, qdd1, dqdd1, why)) return false;
      const double o = sample_at - s * h;
      if (o >= 0 && (o < h || s == m - 1)) {
        // Heun's q over a step of length o (see the file comment).
        qs = x.q + o * x.qd + (0.5 * o * o) * qdd1;
        if constexpr (Sens) dqs = x.S.template topRows<n>() + o * x.S.template bottomRows<n>() + (0.5 * o * o) * dqdd1;
        sample_at = -1;
      }
      mid.q = x.q + h * x.qd;
      mid.qd = x.qd + h * qdd1;
      if constexpr (Sens) {
        mid.S.template topRows<n>() = x.S.template topRows<n>() + h * x.S.template bottomRows<n>();
        mid.S.template bottomRows<n>() = x.S.template bottomRows<n>() + h * dqdd1;
      }
      if (!acceleration<Sens>(phi, mid, u, du, ts + h, qdd2, dqdd2, why)) return false;
      x.q += (0.5 * h) * (x.qd + mid.qd);
      x.qd += (0.5 * h) * (qdd1 + qdd2);
      if constexpr (Sens) {
        x.S.template topRows<n>() += (0.5 * h) * (x.S.template bottomRows<n>() + mid.S.template bottomRows<n>());
        x.S.template bottomRows<n>() += (0.5 * h) * (dqdd1 + dqdd2);
      }
    }
    return true;
  }

  // hold<true> with one set of derivatives per step, taken half a step in (see the file comment).
  // The state goes through exactly hold<false>'s operations: tau is the plain simulation's, bit
  // for bit.
  bool hold_frozen(const Phi& phi, State& x, const Vec& u, const SensQ& du, double length, double t0, double sample_at,
                   Vec& qs, SensQ& dqs, Divergence& why) const {
    const int m = setup_.substeps;
    const double h = length / m;
    typename Model::template ForwardDynamicsDerivatives<double> d;
    Vec qdd1, qdd2;
    SensQ dqdd1, dqdd2, unused;
    State mid;
    for (int s = 0; s < m; ++s) {
      const double ts = t0 + s * h;
      if (!acceleration<false>(phi, x, u, du, ts, qdd1, unused, why)) return false;
      // The Jacobians at the step's midpoint, x + h/2 f(x) (an O(h^2) match of the average of the
      // two stages'): first-stage Jacobians instead lag by h/2, measured 3 % off in d tau.
      mid.q = x.q + (0.5 * h) * x.qd;
      mid.qd = x.qd + (0.5 * h) * qdd1;
      if (!Model::forward_dynamics_derivatives(mid.q, mid.qd, u, phi, d)) {
        why = detail::indefinite_inertia(ts, d.min_pivot);
        return false;
      }
      const auto Sq = x.S.template topRows<n>();
      const auto Sqd = x.S.template bottomRows<n>();
      dqdd1 = d.dphi;
      detail::add_product(dqdd1, d.dq, Sq);
      detail::add_product(dqdd1, d.dqd, Sqd);
      detail::add_product(dqdd1, d.dtau, du);
      const double o = sample_at - s * h;
      if (o >= 0 && (o < h || s == m - 1)) {
        qs = x.q + o * x.qd + (0.5 * o * o) * qdd1;
        dqs = Sq + o * Sqd + (0.5 * o * o) * dqdd1;
        sample_at = -1;
      }
      mid.q = x.q + h * x.qd;
      mid.qd = x.qd + h * qdd1;
      if (!acceleration<false>(phi, mid, u, du, ts + h, qdd2, unused, why)) return false;
      // The second stage with the same Jacobians: its S differs from the first's by h (S_qd, d qdd1),
      // so d qdd2 = d qdd1 + h (d qdd/d q S_qd + d qdd/d qd d qdd1).
      dqdd2 = dqdd1;
      detail::add_product(dqdd2, d.dq, Sqd, h);
      detail::add_product(dqdd2, d.dqd, dqdd1, h);
      x.q += (0.5 * h) * (x.qd + mid.qd);
      x.qd += (0.5 * h) * (qdd1 + qdd2);
      // Heun on S: S_q += h/2 (S_qd + S_qd + h d qdd1), S_qd += h/2 (d qdd1 + d qdd2).
      x.S.template topRows<n>() += h * Sqd + (0.5 * h * h) * dqdd1;
      x.S.template bottomRows<n>() += (0.5 * h) * (dqdd1 + dqdd2);
    }
    return true;
  }

  template <bool Sens>
  bool run(const Phi& phi, preprocess::Channels& tau, SensitivityRows* dtau, preprocess::Channels* q_out,
           Divergence& why) const {
    const double T = period(), d = setup_.delay;
    const int total = pre_cycles_ + cycles_;  // pre-roll cycles, then the recorded ones
    const bool split = setup_.split_at_sampling;
    tau.resize(cycles_, n);
    Eigen::Matrix<double, n, np, Eigen::RowMajor> dtau_row;
    if (q_out) q_out->resize(cycles_, n);

    detail::FfpdSensitivity<n, np> controller(setup_.gains);
    State x;
    x.q = q_ref_.col(0);
    x.qd.setZero();
    controller.template reset<Sens>(x.q);
    Vec u_prev = Vec::Zero(), u, qs = x.q;
    SensQ du_prev, du, dqs;
    if constexpr (Sens) {
      x.S.setZero();
      du_prev.setZero();
      dqs.setZero();
    }
    const double t_first = -pre_cycles_ * T;
    // Without splitting, the first hold (no command yet, as in the twin) ends where the
    // cycle-aligned holds begin.
    if (!split && !hold<Sens>(phi, x, u_prev, du_prev, d, t_first, -1, qs, dqs, why)) return false;

    for (int c = 0; c < total; ++c) {
      const int k = std::max(0, c - pre_cycles_);  // the reference row (the first during pre-roll)
      const double t = t_first + c * T;
      if (split) {
        qs = x.q;
        if constexpr (Sens) dqs = x.S.template topRows<n>();
      }
      for (int j = 0; j < n; ++j) {
        const double error = std::abs(q_ref_(j, k) - qs(j));
        if (!std::isfinite(error)) {
          why = detail::not_finite(t);
          return false;
        }
        if (error > setup_.divergence_error) {
          why = detail::tracking_divergence(t, j, error);
          return false;
        }
      }
      if (c >= pre_cycles_) {
        tau.row(k) = u_prev.transpose();
        if constexpr (Sens) {
          dtau_row = du_prev;
          dtau->row(dtau_row.data());
        }
        if (q_out) q_out->row(k) = qs.transpose();
      }
      controller.template update<Sens>(qs, dqs, q_ref_.col(k), qd_ref_.col(k), qdd_ref_.col(k), u, du);
      if (c == total - 1) break;
      if (split) {
        if (!hold<Sens>(phi, x, u_prev, du_prev, d, t, -1, qs, dqs, why)) return false;
        if (!hold<Sens>(phi, x, u, du, T - d, t + d, -1, qs, dqs, why)) return false;
      } else if (!hold<Sens>(phi, x, u, du, T, t + d, T - d, qs, dqs, why)) {
        return false;
      }
      u_prev = u;
      if constexpr (Sens) du_prev = du;
    }
    return true;
  }

  ClosedLoopSetup setup_;
  int cycles_ = 0, pre_cycles_ = 0;
  Eigen::Matrix<double, n, Eigen::Dynamic> q_ref_, qd_ref_, qdd_ref_;  // column k: reference at k T
};

}  // namespace symoro::identify
