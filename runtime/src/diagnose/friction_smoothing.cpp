// A joint's friction chosen as a whole, at one velocity spread (friction_smoothing.hpp).
#include "friction_smoothing.hpp"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <boost/math/distributions/chi_squared.hpp>

#include "nested_fit.hpp"

namespace symoro::diagnose::detail {

namespace {

bool friction(const Candidate& c) { return friction_law(c.kind); }

// One way to describe a joint's friction: one or two candidates.
struct Option {
  std::vector<const Candidate*> terms;
  double sse = std::numeric_limits<double>::infinity();  // the joint's held-out weighted SSE
};

// Every option among a joint's friction candidates: each alone, and Coulomb friction beside each
// Stribeck term or added row's friction law at the same velocity spread.
std::vector<Option> options(const std::vector<Candidate>& friction) {
  std::vector<Option> out;
  for (const auto& c : friction) out.push_back({{&c}});
  for (const auto& c : friction)
    for (const auto& s : friction)
      if (c.kind == EffectKind::Coulomb && (s.kind == EffectKind::Stribeck || only_when_named(s.kind)) &&
          c.coulomb_velocity == s.coulomb_velocity)
        out.push_back({{&c, &s}});
  return out;
}

}  // namespace

void choose_friction_smoothing(const DesignStack& train, const DesignStack& heldout, const SelectionOptions& selection,
                               const Eigen::VectorXd& weights, std::vector<Candidate>& chosen,
                               std::vector<SelectedEffect>& effects) {
  for (int j = 1; j <= train.joints; ++j) {
    std::vector<Candidate> others;
    std::vector<SelectedEffect> kept, named;
    std::size_t at = chosen.size();  // where the joint's friction goes back: where it was first
    for (std::size_t i = 0; i < chosen.size(); ++i) {
      if (friction(chosen[i]) && chosen[i].joint == j) {
        at = std::min(at, others.size());
        named.push_back(effects[i]);
      } else {
        others.push_back(chosen[i]);
        kept.push_back(effects[i]);
      }
    }
    if (named.empty()) continue;
    // The other effects, refitted without the joint's friction; each option is added to them.
    const Fit without = fit_with_effects(train, heldout, others, weights, selection.max_lag);
    const NestedDesign nd = nested_design(train, heldout, others, without, weights);
    const std::vector<Candidate> friction = friction_options(train, selection.candidates, j);
    std::vector<Option> opts = options(friction);
    const Option* single = nullptr;
    const Option* pair = nullptr;
    // Each candidate's columns once (a column serves its single option and every pair it is in).
    std::vector<Eigen::VectorXd> train_column, heldout_column;
    for (const auto& c : friction) {
      train_column.push_back(effect_columns(c, train, nd.train_state).col(0));
      heldout_column.push_back(effect_columns(c, heldout, nd.heldout_state).col(0));
    }
    for (auto& op : opts) {
      Eigen::MatrixXd Ctr(train.rows(), static_cast<Eigen::Index>(op.terms.size()));
      Eigen::MatrixXd Ch(heldout.rows(), Ctr.cols());
      for (std::size_t k = 0; k < op.terms.size(); ++k) {
        const auto i = static_cast<std::size_t>(op.terms[k] - friction.data());
        Ctr.col(static_cast<Eigen::Index>(k)) = train_column[i];
        Ch.col(static_cast<Eigen::Index>(k)) = heldout_column[i];
      }
      const AddedColumns ac = add_columns(nd, Ctr, Ch);
      if (ac.absorbed || !(ac.theta.minCoeff() > 0)) continue;  // friction opposes motion
      op.sse = joint_sse(heldout, ac.rh1, j);
      const Option*& best = op.terms.size() == 1 ? single : pair;
      if (!best || op.sse < best->sse) best = &op;
    }
    if (!single) continue;  // nothing physical: the forward steps' choice stands
    const bool both = pair && pair->sse <= (1 - selection.min_heldout_gain) * single->sse;
    const Option& pick = both ? *pair : *single;
    // The terms, with the forward step's record where it named the same effect; another gets
    // its Wald statistic in the refit and its held-out gain: a pair's second term over the best
    // single term, a single term over no friction on the joint.
    std::vector<SelectedEffect> picked;
    std::vector<Candidate> terms;
    for (const Candidate* c : pick.terms) terms.push_back(*c);
    std::vector<Candidate> refit = others;
    refit.insert(refit.begin() + static_cast<std::ptrdiff_t>(at), terms.begin(), terms.end());
    std::vector<Eigen::VectorXd> sds;
    Fit f;  // the refit, for a term the forward steps did not name
    for (std::size_t k = 0; k < terms.size(); ++k) {
      SelectedEffect e;
      e.candidate = terms[k];
      bool recorded = false;
      for (const auto& n : named)
        if (n.candidate.kind == terms[k].kind) {
          e.f = n.f, e.p_value = n.p_value, e.heldout_gain = n.heldout_gain;
          recorded = true;
        }
      if (!recorded) {
        if (sds.empty()) f = fit_with_effects(train, heldout, refit, weights, selection.max_lag, &sds);
        const std::size_t i = at + k;
        const double z = sds[i](0) > 0 ? f.theta[i](0) / sds[i](0) : 0.0;
        e.f = z * z;
        e.p_value = boost::math::cdf(boost::math::complement(boost::math::chi_squared_distribution<double>(1), e.f));
        const double before = both ? single->sse : joint_sse(heldout, nd.rh, j);
        e.heldout_gain = before > 0 ? 1 - pick.sse / before : 0.0;
      }
      picked.push_back(e);
    }
    kept.insert(kept.begin() + static_cast<std::ptrdiff_t>(at), picked.begin(), picked.end());
    chosen = refit;
    effects = kept;
  }
}

}  // namespace symoro::diagnose::detail
