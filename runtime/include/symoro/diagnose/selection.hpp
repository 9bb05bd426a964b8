// Forward stepwise selection of missing effects, as a statistician would run it:
//   * every step refits the identified parameters together with the effects chosen so far and
//     one candidate (nested models: the candidate's columns added to the current design);
//   * the nested test uses the joints' residual scales as weights (joints differ by orders
//     of magnitude in torque noise); filtered, densely sampled residuals are strongly
//     autocorrelated, so it is a score test with the score's long-run variance (per joint, the
//     residual's autocovariance up to its first non-positive lag, against the candidate's
//     own column at the same lags): a constant column meets the residual's slow drift in
//     full, a fast one only its fast part (the plain F-test with N / tau_int treats both
//     alike, which lets offsets through and holds delays back);
//   * the level is Bonferroni-corrected over the step's candidates;
//   * a significant candidate must also generalize: on held-out trajectories, refitted with
//     it, the weighted residual of the joints it acts on must fall by at least
//     `min_heldout_gain`, and it must matter in its own units (a delay of at least one log
//     period; any other effect at least `min_effect_torque` rms on a joint);
//   * of those, the one that removes the largest share of the whole held-out weighted
//     residual is taken; the selection stops when no candidate passes;
//   * then every named effect is refitted with all the others and must still stand on its own:
//     its 95 % confidence region (the residual's autocorrelation counted) must exclude half
//     its own size, it must still agree with its physics, and dropping it from the full model
//     must cost its joints `min_heldout_gain` held out. A term named early can be made
//     redundant by a later one, and a small term fitted beside a large one (a Stribeck term
//     after Coulomb, a delay or an offset after a payload) can win a step on the large one's
//     leftovers with an interval that reaches down to nothing. The weakest failing effect is
//     dropped and the rest refitted, until all stand. On clean data it reports nothing.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/diagnose/design_stack.hpp"
#include "symoro/diagnose/effects.hpp"

namespace symoro::diagnose {

struct SelectionOptions {
  double alpha = 1e-3;             // family-wise level of each step
  double min_heldout_gain = 0.02;  // relative fall of the held-out weighted SSE
  // A candidate with fewer parameters whose held-out reduction is within this fraction of the
  // best one's is taken instead (parsimony between near-equals).
  double parsimony = 0.05;
  // An effect whose torque is smaller than this on every joint it acts on (rms over the
  // held-out samples) does not matter: about half a current step of a DYNAMIXEL X servo.
  double min_effect_torque = 0.003;  // N m
  // A delay shorter than this many log periods is the logs' own timing (sample and hold), and
  // not a shift one could apply to the torque.
  double min_delay_periods = 1.0;
  int max_effects = 10;
  int max_lag = 400;  // samples, for the autocorrelation time
  // The backward check: a named effect whose 95 % region reaches this fraction of its own
  // size (or less) is not determined by the data.
  double smallest_fraction = 0.5;
  // s, the sampling-to-command delay the controller description already models (negative: no
  // description). A named actuation delay within its 95 % interval of it, or within
  // min_delay_periods log periods (what a delay must reach to matter), is that delay, not a
  // missing effect, and is dropped.
  double modeled_delay = -1;
  CandidateOptions candidates;
};

struct CandidateTest {
  std::string key, label;
  int columns = 0;
  double f = 0, p_value = 1, df2 = 0;
  double heldout_gain = 0;        // 1 - SSE_after / SSE_before on its joints (held out)
  double heldout_reduction = 0;   // the same over all joints: what ranks the candidates
  double effective_time = 1;      // samples per independent score sample (plain / robust statistic)
  std::vector<double> magnitude;  // its magnitude values (effects.hpp) in this step's fit
  bool matters = false;           // large enough in its own units
  bool absorbed = false;          // its columns lie in the span of the current design
  double effect_rms = 0;          // N m, its torque on the held-out samples, largest joint
  bool physical = true;           // its parameters agree with its physics (effects.hpp)
  bool significant = false, generalizes = false;
};

struct SelectionStep {
  double autocorrelation_time = 1;   // samples per independent sample (pooled over joints)
  double level = 0;                  // alpha / candidates
  std::vector<CandidateTest> tests;  // sorted by held-out reduction, best first
  std::string chosen;                // key, empty when the selection stopped here
};

struct SelectedEffect {
  Candidate candidate;
  Eigen::VectorXd theta, std_dev;  // its parameters in the final fit
  Magnitude magnitude;
  double f = 0, p_value = 1, heldout_gain = 0;  // when it was selected
};

struct Fit {
  Eigen::VectorXd phi;                        // identified parameters
  std::vector<Eigen::VectorXd> theta;         // per selected effect
  Eigen::VectorXd train_rmse, heldout_rmse;   // per joint, N m
  double train_total = 0, heldout_total = 0;  // over all joints and samples
  Eigen::VectorXd train_tau, heldout_tau;     // stacked model torques (with the effects)
};

// An effect the forward steps named and the backward check dropped, with why.
struct DroppedEffect {
  Candidate candidate;
  std::string magnitude;    // as refitted with the others, e.g. "-0.0126 +- 0.0238 N m"
  double size = 0;          // its Wald statistic over the region's bound (< 1: undetermined)
  double heldout_gain = 0;  // what dropping it from the full model costs its joints, held out (NaN: not
                            // asked, its region already failed)
  std::string reason;
};

struct Selection {
  Eigen::VectorXd weights;  // per joint, 1 / residual std of the base fit
  std::vector<SelectionStep> steps;
  std::vector<SelectedEffect> effects;
  std::vector<DroppedEffect> dropped;  // by the backward check, in the order dropped
  Fit before, after;                   // base model alone, and with the selected effects
  std::string stop_reason;
};

Selection select_effects(const DesignStack& train, const DesignStack& heldout, const SelectionOptions& options = {});

// Weighted least squares of y on [W | effect columns] (no selection): what `Selection::after`
// holds, exposed for reports and tests that fix the effects.
// theta_cov: each effect's parameter covariance (the residual's autocorrelation counted, over
// at most max_lag samples: SelectionOptions::max_lag).
Fit fit_with_effects(const DesignStack& train, const DesignStack& heldout, const std::vector<Candidate>& effects,
                     const Eigen::VectorXd& weights, int max_lag, std::vector<Eigen::VectorXd>* theta_sd = nullptr,
                     std::vector<Eigen::MatrixXd>* theta_cov = nullptr);

// Integrated autocorrelation time of the columns of a samples x joints residual along the
// segments (1 + 2 sum of rho_k up to the first non-positive one), per joint.
Eigen::VectorXd autocorrelation_time(const DesignStack& d, const Eigen::MatrixXd& residual, int max_lag);

}  // namespace symoro::diagnose
