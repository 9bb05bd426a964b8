// A whole model-gap diagnosis on two stacks (fitting trajectories and held-out ones): the
// stepwise selection of missing effects (selection.hpp), where the residual is before and
// after them (localize.hpp), a report with figures, and the robot.yaml variant that compiles
// the selected effects into the model (codegen: variant `effects:`).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "symoro/diagnose/backlash_fit.hpp"
#include "symoro/diagnose/design_stack.hpp"
#include "symoro/diagnose/localize.hpp"
#include "symoro/diagnose/selection.hpp"

namespace symoro::diagnose {

struct DiagnosisOptions {
  SelectionOptions selection;
  LocalizeOptions localize;
};

struct Diagnosis {
  std::string robot, model;                 // e.g. "crane_x7", "crane_x7::reduced"
  std::string held_parameters;              // the parameters file when they were held (--params)
  std::vector<std::string> train, heldout;  // trajectory names
  double interval = 0, cutoff = 0;          // s, Hz
  SelectionOptions options;                 // what the selection was run with
  Selection selection;
  std::vector<ResidualSeries> before_series, after_series;  // held out
  Localization before, after;
  // The closed-loop high-band stage (backlash_fit.hpp), when it ran (dynid diagnose runs it with
  // the robot's twin description): play per joint and the refined delay.
  bool backlash_judged = false;
  BacklashFit backlash;
  // When the stage did not run or failed: why (no twin, no references in the log, the
  // simulation refused the robot...). The stages before it are reported all the same.
  std::string backlash_note;
  // The held-out gap against the raw measured torque at the logs' own rate (study/raw_torque.hpp),
  // beside the diagnosis band's: rms per joint and over all, before and after the effects.
  Eigen::VectorXd raw_before, raw_after;
  double raw_total_before = 0, raw_total_after = 0;
  std::string raw_filter;  // the evaluation, one sentence ("" when not scored)
  std::string raw_note;    // why not, when it failed
};

// The stack's segments as residual series, with the stacked model torque.
std::vector<ResidualSeries> residual_series(const DesignStack& d, const Eigen::VectorXd& tau_model);

Diagnosis diagnose(const DesignStack& train, const DesignStack& heldout, const DiagnosisOptions& options = {});

// <dir>/diagnosis.md and <dir>/figures/*.svg; returns the files written.
std::vector<std::filesystem::path> write_diagnosis_report(const Diagnosis& d, const std::filesystem::path& dir);

// The robot.yaml variant (text, indented for `variants:`) that adds the selected effects the
// compiler knows to `base`; empty when there are none. Effects it cannot compile (delay,
// torque constant, backlash) are listed in comments with what to do instead.
std::string variant_yaml(const Diagnosis& d, const std::string& name, const std::string& base);

}  // namespace symoro::diagnose
