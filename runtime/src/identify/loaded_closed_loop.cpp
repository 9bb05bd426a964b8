// ClosedLoopSimulator<Model> (detail/closed_loop_model.hpp: the integration, the sensitivities,
// where the steps lie, and why) written once over a ModelHandle: the same steps, every buffer
// allocated once per simulation. CLIE and closed-loop validation of every robot go through it.
// The joint count is a compile-time size for 2 to 8 joints (instantiated once here, for every
// robot with that many: the sensitivities' n x n and n x np updates then unroll as the fixed-size
// simulator's do, 20 % faster than with run-time sizes), a run-time one otherwise; the parameter
// count always a run-time one. The arithmetic is the same either way.
#include "symoro/identify/loaded_closed_loop.hpp"
#include "symoro/identify/detail/loaded_closed_loop_sizes.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "symoro/identify/detail/closed_loop_model.hpp"

namespace symoro::identify {
namespace {

using Eigen::Dynamic;
using robot::ModelHandle;

// The buffers' types for N joints (Dynamic: the run-time count).
template <int N>
struct Sizes {
  using Vec = Eigen::Matrix<double, N, 1>;
  using Square = Eigen::Matrix<double, N, N>;
  using Sens = Eigen::Matrix<double, N, Dynamic>;                                // n x np
  using SensX = Eigen::Matrix<double, N == Dynamic ? Dynamic : 2 * N, Dynamic>;  // 2n x np
  using SensRow = Eigen::Matrix<double, N, Dynamic, Eigen::RowMajor>;
  using Controller = detail::FfpdSensitivity<N, Dynamic>;
};

template <int N>
class LoadedClosedLoop final : public ClosedLoop {
 public:
  using Vec = typename Sizes<N>::Vec;
  using Square = typename Sizes<N>::Square;
  using Mat = typename Sizes<N>::Sens;
  LoadedClosedLoop(ModelHandle model, ClosedLoopSetup setup, const trajectory::SampledReference& reference)
      : m_(std::move(model)), setup_(std::move(setup)), n_(m_.nq()), np_(m_.np()) {
    detail::check_setup(setup_, n_);
    if (reference.q.rows() != n_)
      throw std::invalid_argument("closed-loop simulation: the reference " + reference.name + " has " +
                                  std::to_string(reference.q.rows()) + " joints, the model " + std::to_string(n_));
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

  int joints() const override { return n_; }
  const std::vector<ParameterInfo>& parameter_info() const override { return m_.parameters(); }
  int cycles() const override { return cycles_; }
  const ClosedLoopSetup& setup() const override { return setup_; }

  bool simulate(const Eigen::VectorXd& phi, preprocess::Channels& tau, preprocess::Channels* dtau, Divergence* why,
                preprocess::Channels* q) const override {
    if (!dtau) return simulate_into(phi, tau, nullptr, why, q);
    struct Store final : SensitivityRows {
      preprocess::Channels& m;
      Eigen::Index k = 0;
      explicit Store(preprocess::Channels& out) : m(out) {}
      void row(const double* d) override { m.row(k++) = Eigen::Map<const Eigen::RowVectorXd>(d, m.cols()); }
    } store(*dtau);
    dtau->resize(cycles_, n_ * np_);
    return simulate_into(phi, tau, &store, why, q);
  }
  bool simulate(const Eigen::VectorXd& phi, preprocess::Channels& tau, SensitivityRows& dtau,
                Divergence* why) const override {
    return simulate_into(phi, tau, &dtau, why, nullptr);
  }

 private:
  struct State {
    Vec q, qd;
    typename Sizes<N>::SensX S;  // 2n x np, q rows first (with sensitivities)
  };
  // S's q rows and qd rows.
  template <class X>
  auto top(X& S) const {
    if constexpr (N == Dynamic)
      return S.topRows(n_);
    else
      return S.template topRows<N>();
  }
  template <class X>
  auto bottom(X& S) const {
    if constexpr (N == Dynamic)
      return S.bottomRows(n_);
    else
      return S.template bottomRows<N>();
  }
  // Everything a simulation writes per step, sized once.
  struct Work {
    Square M, L, fd_dq, fd_dqd, fd_dtau;
    Mat fd_dphi;
    Vec h, D, rhs, qdd1, qdd2;
    Mat dqdd1, dqdd2, unused;
    State mid;
    Work(int n, int np) {
      for (Square* m : {&M, &L, &fd_dq, &fd_dqd, &fd_dtau}) m->resize(n, n);
      for (Mat* m : {&fd_dphi, &dqdd1, &dqdd2, &unused}) m->resize(n, np);
      for (Vec* v : {&h, &D, &rhs, &qdd1, &qdd2, &mid.q, &mid.qd}) v->resize(n);
      mid.S.resize(2 * n, np);
    }
  };

  bool simulate_into(const Eigen::VectorXd& phi, preprocess::Channels& tau, SensitivityRows* dtau, Divergence* why,
                     preprocess::Channels* q) const {
    if (phi.size() != np_)
      throw std::invalid_argument("closed-loop simulation: phi has " + std::to_string(phi.size()) +
                                  " entries, the model " + std::to_string(np_));
    Divergence stop;
    const bool ok = run(dtau != nullptr, phi, tau, dtau, q, stop);
    if (why) *why = ok ? Divergence{} : stop;
    return ok;
  }

  // qdd = M^-1 (u - h) at x, and with sens its derivative d qdd / d phi. False on divergence.
  bool acceleration(bool sens, const Eigen::VectorXd& phi, const State& x, const Vec& u, const Mat& du, double t,
                    Vec& qdd, Mat& dqdd, Work& w, Divergence& why) const {
    if (!x.q.allFinite() || !x.qd.allFinite()) {
      why = detail::not_finite(t);
      return false;
    }
    if (sens) {
      double pivot = 0;
      if (!m_.forward_dynamics_derivatives(x.q.data(), x.qd.data(), u.data(), phi.data(), qdd.data(), w.fd_dq.data(),
                                           w.fd_dqd.data(), w.fd_dtau.data(), w.fd_dphi.data(), &pivot)) {
        why = detail::indefinite_inertia(t, pivot);
        return false;
      }
      if (!qdd.allFinite()) {
        why = detail::not_finite(t);
        return false;
      }
      dqdd = w.fd_dphi;
      detail::add_product(dqdd, w.fd_dq, top(x.S));
      detail::add_product(dqdd, w.fd_dqd, bottom(x.S));
      detail::add_product(dqdd, w.fd_dtau, du);
      return true;
    }
    m_.inertia(x.q.data(), phi.data(), w.M.data());
    m_.nonlinear_effects(x.q.data(), x.qd.data(), phi.data(), w.h.data());
    w.rhs = u - w.h;
    const double pivot = detail::solve_spd(n_, w.M.data(), w.rhs.data(), qdd.data(), w.L.data(), w.D.data());
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

  bool hold(bool sens, const Eigen::VectorXd& phi, State& x, const Vec& u, const Mat& du, double length, double t0,
            double sample_at, Vec& qs, Mat& dqs, Work& w, Divergence& why) const {
    if (!(length > 0)) return true;
    if (sens && !setup_.exact_sensitivities) return hold_frozen(phi, x, u, du, length, t0, sample_at, qs, dqs, w, why);
    const int m = setup_.substeps;
    const double h = length / m;
    State& mid = w.mid;
    for (int s = 0; s < m; ++s) {
      const double ts = t0 + s * h;
      if (!acceleration(sens, phi, x, u, du, ts, w.qdd1, w.dqdd1, w, why)) return false;
      const double o = sample_at - s * h;
      if (o >= 0 && (o < h || s == m - 1)) {
        qs = x.q + o * x.qd + (0.5 * o * o) * w.qdd1;
        if (sens) dqs = top(x.S) + o * bottom(x.S) + (0.5 * o * o) * w.dqdd1;
        sample_at = -1;
      }
      mid.q = x.q + h * x.qd;
      mid.qd = x.qd + h * w.qdd1;
      if (sens) {
        top(mid.S) = top(x.S) + h * bottom(x.S);
        bottom(mid.S) = bottom(x.S) + h * w.dqdd1;
      }
      if (!acceleration(sens, phi, mid, u, du, ts + h, w.qdd2, w.dqdd2, w, why)) return false;
      x.q += (0.5 * h) * (x.qd + mid.qd);
      x.qd += (0.5 * h) * (w.qdd1 + w.qdd2);
      if (sens) {
        top(x.S) += (0.5 * h) * (bottom(x.S) + bottom(mid.S));
        bottom(x.S) += (0.5 * h) * (w.dqdd1 + w.dqdd2);
      }
    }
    return true;
  }

  bool hold_frozen(const Eigen::VectorXd& phi, State& x, const Vec& u, const Mat& du, double length, double t0,
                   double sample_at, Vec& qs, Mat& dqs, Work& w, Divergence& why) const {
    const int m = setup_.substeps;
    const double h = length / m;
    State& mid = w.mid;
    for (int s = 0; s < m; ++s) {
      const double ts = t0 + s * h;
      if (!acceleration(false, phi, x, u, du, ts, w.qdd1, w.unused, w, why)) return false;
      mid.q = x.q + (0.5 * h) * x.qd;
      mid.qd = x.qd + (0.5 * h) * w.qdd1;
      double pivot = 0;
      if (!m_.forward_dynamics_derivatives(mid.q.data(), mid.qd.data(), u.data(), phi.data(), w.qdd2.data(),
                                           w.fd_dq.data(), w.fd_dqd.data(), w.fd_dtau.data(), w.fd_dphi.data(),
                                           &pivot)) {
        why = detail::indefinite_inertia(ts, pivot);
        return false;
      }
      const auto Sq = top(x.S);
      const auto Sqd = bottom(x.S);
      w.dqdd1 = w.fd_dphi;
      detail::add_product(w.dqdd1, w.fd_dq, Sq);
      detail::add_product(w.dqdd1, w.fd_dqd, Sqd);
      detail::add_product(w.dqdd1, w.fd_dtau, du);
      const double o = sample_at - s * h;
      if (o >= 0 && (o < h || s == m - 1)) {
        qs = x.q + o * x.qd + (0.5 * o * o) * w.qdd1;
        dqs = Sq + o * Sqd + (0.5 * o * o) * w.dqdd1;
        sample_at = -1;
      }
      mid.q = x.q + h * x.qd;
      mid.qd = x.qd + h * w.qdd1;
      if (!acceleration(false, phi, mid, u, du, ts + h, w.qdd2, w.unused, w, why)) return false;
      w.dqdd2 = w.dqdd1;
      detail::add_product(w.dqdd2, w.fd_dq, Sqd, h);
      detail::add_product(w.dqdd2, w.fd_dqd, w.dqdd1, h);
      x.q += (0.5 * h) * (x.qd + mid.qd);
      x.qd += (0.5 * h) * (w.qdd1 + w.qdd2);
      top(x.S) += h * Sqd + (0.5 * h * h) * w.dqdd1;
      bottom(x.S) += (0.5 * h) * (w.dqdd1 + w.dqdd2);
    }
    return true;
  }

  bool run(bool sens, const Eigen::VectorXd& phi, preprocess::Channels& tau, SensitivityRows* dtau,
           preprocess::Channels* q_out, Divergence& why) const {
    const double T = period(), d = setup_.delay;
    const int total = pre_cycles_ + cycles_;
    const bool split = setup_.split_at_sampling;
    tau.resize(cycles_, n_);
    typename Sizes<N>::SensRow dtau_row;
    dtau_row.resize(n_, np_);
    if (q_out) q_out->resize(cycles_, n_);

    Work w(n_, np_);
    typename Sizes<N>::Controller controller(setup_.gains, np_);
    State x;
    x.q = q_ref_.col(0);
    x.qd.resize(n_);
    x.qd.setZero();
    x.S.resize(2 * n_, np_);
    if (sens)
      controller.template reset<true>(x.q);
    else
      controller.template reset<false>(x.q);
    Vec u_prev, u, qs = x.q;
    u_prev.resize(n_);
    u_prev.setZero();
    u.resize(n_);
    Mat du_prev, du, dqs;
    for (Mat* m : {&du_prev, &du, &dqs}) m->resize(n_, np_);
    if (sens) {
      x.S.setZero();
      du_prev.setZero();
      dqs.setZero();
    }
    const double t_first = -pre_cycles_ * T;
    if (!split && !hold(sens, phi, x, u_prev, du_prev, d, t_first, -1, qs, dqs, w, why)) return false;

    for (int c = 0; c < total; ++c) {
      const int k = std::max(0, c - pre_cycles_);
      const double t = t_first + c * T;
      if (split) {
        qs = x.q;
        if (sens) dqs = top(x.S);
      }
      for (int j = 0; j < n_; ++j) {
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
        if (sens) {
          dtau_row = du_prev;
          dtau->row(dtau_row.data());
        }
        if (q_out) q_out->row(k) = qs.transpose();
      }
      if (sens)
        controller.template update<true>(qs, dqs, q_ref_.col(k), qd_ref_.col(k), qdd_ref_.col(k), u, du);
      else
        controller.template update<false>(qs, dqs, q_ref_.col(k), qd_ref_.col(k), qdd_ref_.col(k), u, du);
      if (c == total - 1) break;
      if (split) {
        if (!hold(sens, phi, x, u_prev, du_prev, d, t, -1, qs, dqs, w, why)) return false;
        if (!hold(sens, phi, x, u, du, T - d, t + d, -1, qs, dqs, w, why)) return false;
      } else if (!hold(sens, phi, x, u, du, T, t + d, T - d, qs, dqs, w, why)) {
        return false;
      }
      u_prev = u;
      if (sens) du_prev = du;
    }
    return true;
  }

  ModelHandle m_;
  ClosedLoopSetup setup_;
  int n_, np_;
  int cycles_ = 0, pre_cycles_ = 0;
  Eigen::MatrixXd q_ref_, qd_ref_, qdd_ref_;  // n x cycles: column k, the reference at k T
};

}  // namespace

std::unique_ptr<ClosedLoop> closed_loop(const robot::ModelHandle& model, const ClosedLoopSetup& setup,
                                        const trajectory::SampledReference& reference) {
  switch (model.nq()) {
    case 2:
      return std::make_unique<LoadedClosedLoop<2>>(model, setup, reference);
    case 3:
      return std::make_unique<LoadedClosedLoop<3>>(model, setup, reference);
    case 4:
      return std::make_unique<LoadedClosedLoop<4>>(model, setup, reference);
    case 5:
      return std::make_unique<LoadedClosedLoop<5>>(model, setup, reference);
    case 6:
      return std::make_unique<LoadedClosedLoop<6>>(model, setup, reference);
    case 7:
      return std::make_unique<LoadedClosedLoop<7>>(model, setup, reference);
    case 8:
      return std::make_unique<LoadedClosedLoop<8>>(model, setup, reference);
    default:
      return detail::closed_loop_run_time_sizes(model, setup, reference);
  }
}

std::unique_ptr<ClosedLoop> detail::closed_loop_run_time_sizes(const robot::ModelHandle& model,
                                                               const ClosedLoopSetup& setup,
                                                               const trajectory::SampledReference& reference) {
  return std::make_unique<LoadedClosedLoop<Dynamic>>(model, setup, reference);
}

}  // namespace symoro::identify
