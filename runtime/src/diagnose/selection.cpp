#include "symoro/diagnose/selection.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/fisher_f.hpp>
#include <fmt/format.h>

#include "friction_smoothing.hpp"
#include "nested_fit.hpp"

namespace symoro::diagnose {

namespace {

using detail::base_state;
using detail::design;
using detail::free_parameters;
using detail::heldout_sse;
using detail::joint_rms;
using detail::linearized;
using detail::per_sample;
using detail::pooled_time;
using detail::row_weights;
using detail::Solve;
using detail::state_of;
using detail::weighted_ls;

// The stack's segments as [begin, end) sample ranges (each segment is one contiguous piece).
std::vector<std::pair<Eigen::Index, Eigen::Index>> segment_ranges(const DesignStack& d) {
  std::vector<std::pair<Eigen::Index, Eigen::Index>> out;
  const auto S = static_cast<Eigen::Index>(d.samples());
  for (Eigen::Index a = 0, b = 0; a < S; a = b) {
    while (b < S && d.segment[static_cast<std::size_t>(b)] == d.segment[static_cast<std::size_t>(a)]) ++b;
    out.emplace_back(a, b);
  }
  return out;
}

// sum_s x_s x_{s+k} over the pairs of samples k apart within one segment.
double lagged_product(const std::vector<std::pair<Eigen::Index, Eigen::Index>>& segments, const Eigen::VectorXd& x,
                      int k) {
  double c = 0;
  for (const auto& [a, b] : segments)
    if (b - a > k) c += x.segment(a, b - a - k).dot(x.segment(a + k, b - a - k));
  return c;
}

// Per joint, the residual's autocovariance gamma(0..L) along the segments, cut before the first
// non-positive autocorrelation (the window of autocorrelation_time()).
std::vector<std::vector<double>> autocovariance(const DesignStack& d, const Eigen::MatrixXd& r, int max_lag) {
  const int S = d.samples();
  const auto segments = segment_ranges(d);
  std::vector<std::vector<double>> g(static_cast<std::size_t>(r.cols()));
  for (Eigen::Index j = 0; j < r.cols(); ++j) {
    const Eigen::VectorXd x = r.col(j);
    const double var = x.squaredNorm();
    g[j].push_back(var / std::max(S, 1));
    if (!(var > 0)) continue;
    for (int k = 1; k <= max_lag && k < S; ++k) {
      const double c = lagged_product(segments, x, k);
      if (c <= 0) break;
      g[j].push_back(c / S);
    }
  }
  return g;
}

// Long-run covariance of the score Z'e when e has the per-joint autocovariances g (joints
// uncorrelated): sum over joints and lags |k| <= L_j of g_j(k) sum_s z_{s,j} z_{s+k,j}'.
// With white errors it is sigma^2 Z'Z, the classical F-test's; a slowly varying column (an
// offset) meets the residual's full autocorrelation, a fast one (a delay) little of it.
Eigen::MatrixXd score_covariance(const DesignStack& d, const Eigen::MatrixXd& Z,
                                 const std::vector<std::vector<double>>& g) {
  const int n = d.joints, S = d.samples();
  const Eigen::Index m = Z.cols();
  const auto segments = segment_ranges(d);
  Eigen::MatrixXd V = Eigen::MatrixXd::Zero(m, m), Ck(m, m);
  for (int j = 0; j < n; ++j) {
    Eigen::MatrixXd Zj(S, m);
    for (int s = 0; s < S; ++s) Zj.row(s) = Z.row(static_cast<Eigen::Index>(s) * n + j);
    if (Zj.squaredNorm() == 0) continue;
    V += g[j][0] * Zj.transpose() * Zj;
    for (std::size_t k = 1; k < g[j].size(); ++k) {
      // Within each segment, rows s against rows s + k: one product per segment and lag.
      const auto lag = static_cast<Eigen::Index>(k);
      Ck.setZero();
      for (const auto& [a, b] : segments)
        if (b - a > lag)
          Ck.noalias() += Zj.middleRows(a, b - a - lag).transpose() * Zj.middleRows(a + lag, b - a - lag);
      V += g[j][k] * (Ck + Ck.transpose());
    }
  }
  return V;
}

double log_period(const DesignStack& d) { return d.base_interval > 0 ? d.base_interval : d.interval; }

// Whether an effect is large enough to act on, in its own terms: a delay against the logs'
// period (a shift below one sample is not a remedy one can apply, and the logs' own sample and
// hold sits there), every other effect against the torque resolution on its largest joint.
bool matters(const Candidate& c, const CandidateTest& t, const DesignStack& d, const SelectionOptions& options) {
  if (c.kind == EffectKind::ActuationDelay) {
    return !t.magnitude.empty() && std::abs(t.magnitude[0]) >= options.min_delay_periods * log_period(d);
  }
  return t.effect_rms >= options.min_effect_torque;
}

// The backward check (selection.hpp): every chosen effect refitted with all the others; the
// weakest of those that no longer stand is dropped, and the rest refitted, until all stand.
void backward_check(const DesignStack& train, const DesignStack& heldout, const SelectionOptions& options,
                    const Eigen::VectorXd& weights, std::vector<Candidate>& chosen, Selection& sel) {
  while (!chosen.empty()) {
    std::vector<Eigen::VectorXd> sds;
    std::vector<Eigen::MatrixXd> covs;
    const Fit full = fit_with_effects(train, heldout, chosen, weights, options.max_lag, &sds, &covs);
    int worst = -1;
    double worst_weakness = 0;
    DroppedEffect drop;
    for (std::size_t i = 0; i < chosen.size(); ++i) {
      const Candidate& c = chosen[i];
      const Eigen::VectorXd& theta = full.theta[i];
      const Eigen::Index m = theta.size();
      // The region {x : (x - theta)' C^-1 (x - theta) <= chi2_m(0.95)} holds f theta when
      // (1 - f)^2 theta' C^-1 theta <= chi2_m: the effect is determined when its Wald statistic
      // exceeds chi2_m / (1 - f)^2.
      const Eigen::LDLT<Eigen::MatrixXd> cf(covs[i]);
      const double wald = cf.info() == Eigen::Success ? theta.dot(cf.solve(theta)) : 0.0;
      const boost::math::chi_squared_distribution<double> chi2(static_cast<double>(m));
      const double bound = boost::math::quantile(chi2, 0.95) / std::pow(1 - options.smallest_fraction, 2);
      const double size = wald / bound;
      // What dropping it costs its joints held out (a refit without it): not needed for an effect
      // its own region already fails (the weakest by size).
      auto heldout_gain = [&] {
        std::vector<int> on;
        if (effect_info(c.kind).row->scope == EffectScope::Joint) on.push_back(c.joint);
        std::vector<Candidate> others = chosen;
        others.erase(others.begin() + static_cast<std::ptrdiff_t>(i));
        const Fit without = fit_with_effects(train, heldout, others, weights, options.max_lag);
        const double s0 = heldout_sse(without, weights, on, heldout.samples()),
                     s1 = heldout_sse(full, weights, on, heldout.samples());
        return s0 > 0 ? 1 - s1 / s0 : 0.0;
      };
      const double gain = size < 1 ? std::numeric_limits<double>::quiet_NaN() : heldout_gain();
      std::string reason;
      if (!physical(c, theta))
        reason = "refitted with the others, its parameters contradict its physics";
      else if (c.kind == EffectKind::ActuationDelay && options.modeled_delay >= 0 &&
               std::abs(theta(0) - options.modeled_delay) <= std::max(1.96 * std::sqrt(std::max(0.0, covs[i](0, 0))),
                                                                      options.min_delay_periods * log_period(train)))
        reason = fmt::format("refitted with the others, it is the {:.2f} ms the controller description already models",
                             1e3 * options.modeled_delay);
      else if (size < 1)
        reason = fmt::format("refitted with the others, its 95 % region reaches {:.0f} % of its size or less",
                             100 * options.smallest_fraction);
      else if (gain < options.min_heldout_gain)
        reason = fmt::format(
            "refitted with the others, it lowers its joints' held-out residual by {:.1f} % (under {:.0f} %)",
            100 * gain, 100 * options.min_heldout_gain);
      if (reason.empty()) continue;
      // The weakest: the smallest size, held-out gain breaking ties among determined ones.
      const double weakness = size < 1 ? size : 1 + std::max(0.0, gain);
      if (worst < 0 || weakness < worst_weakness) {
        worst = static_cast<int>(i);
        worst_weakness = weakness;
        drop.candidate = c;
        drop.magnitude = magnitude(c, theta, sds[i]).text;
        drop.size = size;
        drop.heldout_gain = gain;
        drop.reason = reason;
      }
    }
    if (worst < 0) return;
    sel.dropped.push_back(drop);
    chosen.erase(chosen.begin() + worst);
    sel.effects.erase(sel.effects.begin() + worst);
  }
}

}  // namespace

Eigen::VectorXd autocorrelation_time(const DesignStack& d, const Eigen::MatrixXd& r, int max_lag) {
  const int S = d.samples();
  const auto segments = segment_ranges(d);
  Eigen::VectorXd out = Eigen::VectorXd::Ones(r.cols());
  for (Eigen::Index j = 0; j < r.cols(); ++j) {
    const Eigen::VectorXd x = r.col(j);
    const double var = x.squaredNorm();
    if (!(var > 0)) continue;
    double sum = 0;
    for (int k = 1; k <= max_lag && k < S; ++k) {
      const double rho = lagged_product(segments, x, k) / var;
      if (rho <= 0) break;
      sum += rho;
    }
    out(j) = 1 + 2 * sum;
  }
  return out;
}

Fit fit_with_effects(const DesignStack& train, const DesignStack& heldout, const std::vector<Candidate>& effects,
                     const Eigen::VectorXd& weights, int max_lag, std::vector<Eigen::VectorXd>* theta_sd,
                     std::vector<Eigen::MatrixXd>* theta_cov) {
  if (heldout.held() != train.held())
    throw std::invalid_argument("fit_with_effects: parameters held in one stack only");
  const Eigen::Index np = free_parameters(train);
  const Eigen::VectorXd rw = row_weights(train, weights);
  const Eigen::VectorXd y = train.target();
  // Start from the base fit; linearized effects are re-evaluated about the latest fit.
  Eigen::MatrixXd A = train.W.leftCols(np);
  Solve base = weighted_ls(A, y, rw, 1.0);
  FitState st = base_state(train, base.beta), sh = base_state(heldout, base.beta);
  Solve s = base;
  const int iterations = linearized(effects) ? 3 : 1;
  for (int it = 0; it < iterations; ++it) {
    A = design(train, effects, st);
    s = weighted_ls(A, y, rw, 1.0);
    const Eigen::MatrixXd Ah = design(heldout, effects, sh);
    st = state_of(train, A, s.beta, np);
    sh = state_of(heldout, Ah, s.beta, np);
  }
  // Standard deviations with the residual's autocorrelation time.
  const Eigen::VectorXd r = A.cols() ? Eigen::VectorXd(y - A * s.beta) : y;
  const Eigen::MatrixXd rs = per_sample(train, rw.cwiseProduct(r));
  const double tau_int = pooled_time(autocorrelation_time(train, rs, max_lag));
  const Solve sd = weighted_ls(A, y, rw, tau_int);
  Fit f;
  f.phi = train.held() ? train.held_phi : Eigen::VectorXd(s.beta.head(np));
  Eigen::Index c = np;
  for (const auto& e : effects) {
    const Eigen::Index m = static_cast<Eigen::Index>(e.parameters.size());
    f.theta.push_back(s.beta.segment(c, m));
    if (theta_sd) theta_sd->push_back(sd.sd.segment(c, m));
    if (theta_cov) theta_cov->push_back(sd.cov.block(c, c, m, m));
    c += m;
  }
  f.train_tau = st.tau_model;
  f.train_rmse = joint_rms(train, r);
  f.train_total = std::sqrt(r.squaredNorm() / std::max<Eigen::Index>(1, r.size()));
  if (heldout.samples() > 0) {
    f.heldout_tau = sh.tau_model;
    const Eigen::VectorXd rh = heldout.stacked(heldout.tau) - sh.tau_model;
    f.heldout_rmse = joint_rms(heldout, rh);
    f.heldout_total = std::sqrt(rh.squaredNorm() / std::max<Eigen::Index>(1, rh.size()));
  }
  return f;
}

namespace {

// One candidate's test at a step of the forward selection, against the nested design of the
// effects chosen so far: its columns added (or found absorbed by the model's), the score test
// with the residual's autocorrelation at the step's level, then the refit's held-out gain on
// the joints it acts on, its size there, and whether it is physical and matters.
CandidateTest test_candidate(const Candidate& c, const detail::NestedDesign& nd, const DesignStack& train,
                             const DesignStack& heldout, const SelectionOptions& options, double level) {
  const int n = train.joints;
  const Eigen::MatrixXd& As = nd.As;
  const Eigen::VectorXd& r = nd.r;
  const double rss0 = r.squaredNorm();
  const Eigen::Index N = nd.A.rows(), p = nd.A.cols();
  const double dof = static_cast<double>(N) / static_cast<double>(std::max<Eigen::Index>(1, N - p));
  CandidateTest t;
  t.key = c.key();
  t.label = c.label();
  const Eigen::MatrixXd Ctr = effect_columns(c, train, nd.train_state);
  const Eigen::MatrixXd Ch = effect_columns(c, heldout, nd.heldout_state);
  const detail::AddedColumns ac = detail::add_columns(nd, Ctr, Ch);
  t.columns = static_cast<int>(Ctr.cols());
  if (ac.absorbed) {
    t.absorbed = true;
    return t;
  }
  const Eigen::Index m = Ctr.cols();
  const Eigen::MatrixXd& C = ac.C;
  const Eigen::VectorXd& Cr = ac.Cr;
  const Eigen::VectorXd& theta_s = ac.theta_s;
  const double reduction = ac.reduction;
  // Test with the long-run (autocorrelation-consistent) variance of the score, the
  // candidate's own columns against the autocorrelation of the residual the candidate
  // leaves (the alternative's): an offset is judged against the residual's slow drift, a
  // fast column against the faster part. Not the residual before it: where the candidate
  // is the dominant misfit (a constant offset a joint's gravity columns cannot absorb),
  // that residual is the effect itself, its uncentred autocovariance stays at the
  // effect's square over every lag, and the effect capped its own F (F 9-13 for an
  // offset that removed 99 % of the held-out error).
  const Eigen::MatrixXd Z = C - As * ac.K;
  const Eigen::MatrixXd r1 = per_sample(train, Eigen::VectorXd(r - Z * theta_s));
  const Eigen::MatrixXd V = dof * score_covariance(train, Z, autocovariance(train, r1, options.max_lag));
  const double df2 = static_cast<double>(N) / pooled_time(autocorrelation_time(train, r1, options.max_lag)) -
                     static_cast<double>(p + m);
  t.df2 = df2;
  const Eigen::LDLT<Eigen::MatrixXd> Vf(V);
  const double stat = Vf.info() == Eigen::Success ? Cr.dot(Vf.solve(Cr)) : 0.0;
  t.effective_time = stat > 0 ? (reduction / (rss0 / static_cast<double>(N - p))) / stat : 1.0;
  if (df2 > 1 && stat > 0) {
    t.f = stat / static_cast<double>(m);
    const boost::math::fisher_f_distribution<double> dist(static_cast<double>(m), df2);
    t.p_value = boost::math::cdf(boost::math::complement(dist, t.f));
  }
  t.significant = t.p_value < level;
  // Held out: the refit with the candidate, on the joints it acts on.
  const Eigen::VectorXd& theta = ac.theta;
  const Eigen::VectorXd& rh = nd.rh;
  const Eigen::VectorXd& rh1 = ac.rh1;
  double sse0 = 0, sse1 = 0, total0 = 0, total1 = 0;
  std::vector<bool> acts_on(n, false);
  for (int j = 0; j < n; ++j) {
    double acts = 0;
    for (int s = 0; s < train.samples(); ++s) acts += Ctr.row(static_cast<Eigen::Index>(s) * n + j).squaredNorm();
    acts_on[j] = acts > 0;
    for (int s = 0; s < heldout.samples(); ++s) {
      const Eigen::Index i = static_cast<Eigen::Index>(s) * n + j;
      total0 += rh(i) * rh(i);
      total1 += rh1(i) * rh1(i);
      if (!acts_on[j]) continue;
      sse0 += rh(i) * rh(i);
      sse1 += rh1(i) * rh1(i);
    }
  }
  t.heldout_gain = sse0 > 0 ? 1 - sse1 / sse0 : 0;
  t.heldout_reduction = total0 > 0 ? 1 - total1 / total0 : 0;
  const Eigen::VectorXd effect_h = Ch * theta;
  t.effect_rms = 0;
  for (int j = 0; j < n && heldout.samples() > 0; ++j) {
    if (!(acts_on[j])) continue;
    double ss = 0;
    for (int s = 0; s < heldout.samples(); ++s) ss += std::pow(effect_h(static_cast<Eigen::Index>(s) * n + j), 2);
    t.effect_rms = std::max(t.effect_rms, std::sqrt(ss / heldout.samples()));
  }
  t.physical = physical(c, theta);
  t.magnitude = magnitude(c, theta, Eigen::VectorXd::Zero(theta.size())).values;
  t.matters = matters(c, t, train, options);
  t.generalizes = t.heldout_gain >= options.min_heldout_gain && t.matters && t.physical;
  return t;
}

// Parsimony: a candidate with fewer parameters that removes nearly as much (within
// options.parsimony of the best) is taken instead. Position harmonics of a joint whose range is
// limited mimic a constant offset with four columns for one, and won by 1 % of the held-out
// residual over the offset that was there (RX-90 joint 3). tests[i] is pool[i]'s; the indices
// are into `all`.
int parsimonious(int best, double best_reduction, const std::vector<const Candidate*>& pool,
                 const std::vector<Candidate>& all, const std::vector<CandidateTest>& tests,
                 const SelectionOptions& options) {
  int fewest = best, fewest_columns = 0;
  for (std::size_t i = 0; i < pool.size(); ++i)
    if (pool[i] == &all[static_cast<std::size_t>(best)]) fewest_columns = tests[i].columns;
  for (std::size_t i = 0; i < pool.size(); ++i) {
    const CandidateTest& t = tests[i];
    if (t.significant && t.generalizes && t.heldout_reduction >= (1 - options.parsimony) * best_reduction &&
        t.columns < fewest_columns) {
      fewest = static_cast<int>(pool[i] - all.data());
      fewest_columns = t.columns;
    }
  }
  return fewest;
}

}  // namespace

Selection select_effects(const DesignStack& train, const DesignStack& heldout, const SelectionOptions& options) {
  Selection sel;
  const int n = train.joints;
  // Weights from the base model's unweighted residual: 1 / std per joint.
  {
    const Fit plain = fit_with_effects(train, heldout, {}, Eigen::VectorXd::Ones(n), options.max_lag);
    sel.weights = plain.train_rmse.cwiseMax(1e-9).cwiseInverse();
  }
  sel.before = fit_with_effects(train, heldout, {}, sel.weights, options.max_lag);
  const std::vector<Candidate> all = candidates(train, options.candidates);
  std::vector<Candidate> chosen;
  std::set<std::string> taken;  // "<effect>:<joint>": one Stribeck velocity per joint, once
  auto slot = [](const Candidate& c) { return std::string(effect_info(c.kind).name) + ":" + std::to_string(c.joint); };

  Fit current = sel.before;
  while (static_cast<int>(chosen.size()) < options.max_effects) {
    const detail::NestedDesign nd = detail::nested_design(train, heldout, chosen, current, sel.weights);
    SelectionStep step;
    step.autocorrelation_time = pooled_time(autocorrelation_time(train, per_sample(train, nd.r), options.max_lag));
    std::vector<const Candidate*> pool;
    for (const auto& c : all)
      if (!taken.count(slot(c))) pool.push_back(&c);
    if (pool.empty()) {
      sel.stop_reason = "every candidate is in the model";
      break;
    }
    step.level = options.alpha / static_cast<double>(pool.size());
    int best = -1;
    double best_reduction = 0;
    for (const Candidate* c : pool) {
      const CandidateTest t = test_candidate(*c, nd, train, heldout, options, step.level);
      step.tests.push_back(t);
      // Of the admissible candidates, the one that removes most of the held-out residual (all
      // joints, weighted): the out-of-sample form of forward selection's largest RSS drop. A
      // gain relative to the candidate's own joints would favour one-joint terms.
      if (t.significant && t.generalizes && t.heldout_reduction > best_reduction) {
        best_reduction = t.heldout_reduction;
        best = static_cast<int>(c - all.data());
      }
    }
    if (best >= 0) best = parsimonious(best, best_reduction, pool, all, step.tests, options);
    std::sort(step.tests.begin(), step.tests.end(),
              [](const CandidateTest& a, const CandidateTest& b) { return a.heldout_reduction > b.heldout_reduction; });
    if (best < 0) {
      sel.stop_reason = "no candidate is significant and generalizes";
      sel.steps.push_back(step);
      break;
    }
    const Candidate& c = all[static_cast<std::size_t>(best)];
    step.chosen = c.key();
    for (const auto& t : step.tests)
      if (t.key == c.key()) {
        SelectedEffect e;
        e.candidate = c;
        e.f = t.f;
        e.p_value = t.p_value;
        e.heldout_gain = t.heldout_gain;
        sel.effects.push_back(e);
      }
    sel.steps.push_back(step);
    chosen.push_back(c);
    taken.insert(slot(c));
    current = fit_with_effects(train, heldout, chosen, sel.weights, options.max_lag);
  }
  if (sel.stop_reason.empty()) sel.stop_reason = "the maximum number of effects was reached";
  detail::choose_friction_smoothing(train, heldout, options, sel.weights, chosen, sel.effects);
  backward_check(train, heldout, options, sel.weights, chosen, sel);
  std::vector<Eigen::VectorXd> sds;
  sel.after = fit_with_effects(train, heldout, chosen, sel.weights, options.max_lag, &sds);
  for (std::size_t i = 0; i < sel.effects.size(); ++i) {
    sel.effects[i].theta = sel.after.theta[i];
    sel.effects[i].std_dev = sds[i];
    sel.effects[i].magnitude = magnitude(sel.effects[i].candidate, sel.after.theta[i], sds[i]);
  }
  return sel;
}

}  // namespace symoro::diagnose
