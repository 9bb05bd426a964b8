// Forward stepwise selection of missing effects, as a statistician would run it:
//   * every step refits the identified parameters together with the effects chosen so far and
//     one candidate (nested models: the candidate's columns added to the current design);
//   * the nested F-test uses the joints' residual scales as weights (joints differ by orders
//     of magnitude in torque noise) and an effective sample size: filtered, densely sampled
//     residuals are strongly autocorrelated, so N is divided by the integrated
//     autocorrelation time of the current residual (else every candidate is "significant");
//   * the level is Bonferroni-corrected over the step's candidates;
//   * a significant candidate must also generalize: on held-out trajectories, refitted with
//     it, the weighted residual of the joints it acts on must fall by at least
//     `min_heldout_gain`;
//   * of those, the one with the largest held-out gain is taken; the selection stops when no
//     candidate passes. On clean data it reports nothing.
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
  // An effect whose torque is smaller than this on every joint it acts on (rms over the
  // held-out samples) does not matter: about half a current step of a DYNAMIXEL X servo.
  double min_effect_torque = 0.003;  // N m
  int max_effects = 10;
  int max_lag = 400;               // samples, for the autocorrelation time
  CandidateOptions candidates;
};

struct CandidateTest {
  std::string key, label;
  int columns = 0;
  double f = 0, p_value = 1, df2 = 0;
  double heldout_gain = 0;        // 1 - SSE_after / SSE_before on its joints (held out)
  bool absorbed = false;          // its columns lie in the span of the current design
  double effect_rms = 0;          // N m, its torque on the held-out samples, largest joint
  bool physical = true;           // its parameters agree with its physics (effects.hpp)
  bool significant = false, generalizes = false;
};

struct SelectionStep {
  double autocorrelation_time = 1;  // samples per independent sample (pooled over joints)
  double level = 0;                 // alpha / candidates
  std::vector<CandidateTest> tests;  // sorted by held-out gain, best first
  std::string chosen;                // key, empty when the selection stopped here
};

struct SelectedEffect {
  Candidate candidate;
  Eigen::VectorXd theta, std_dev;  // its parameters in the final fit
  Magnitude magnitude;
  double f = 0, p_value = 1, heldout_gain = 0;  // when it was selected
};

struct Fit {
  Eigen::VectorXd phi;              // identified parameters
  std::vector<Eigen::VectorXd> theta;  // per selected effect
  Eigen::VectorXd train_rmse, heldout_rmse;  // per joint, N m
  double train_total = 0, heldout_total = 0;  // over all joints and samples
  Eigen::VectorXd train_tau, heldout_tau;  // stacked model torques (with the effects)
};

struct Selection {
  Eigen::VectorXd weights;          // per joint, 1 / residual std of the base fit
  std::vector<SelectionStep> steps;
  std::vector<SelectedEffect> effects;
  Fit before, after;                // base model alone, and with the selected effects
  std::string stop_reason;
};

Selection select_effects(const DesignStack& train, const DesignStack& heldout, const SelectionOptions& options = {});

// Weighted least squares of y on [W | effect columns] (no selection): what `Selection::after`
// holds, exposed for reports and tests that fix the effects.
Fit fit_with_effects(const DesignStack& train, const DesignStack& heldout, const std::vector<Candidate>& effects,
                     const Eigen::VectorXd& weights, std::vector<Eigen::VectorXd>* theta_sd = nullptr);

// Integrated autocorrelation time of the columns of a samples x joints residual along the
// segments (1 + 2 sum of rho_k up to the first non-positive one), per joint.
Eigen::VectorXd autocorrelation_time(const DesignStack& d, const Eigen::MatrixXd& residual, int max_lag);

}  // namespace symoro::diagnose
