// dynid diagnose's options and its entry, compiled per model of each robot (any variant:
// --model) in generated units; the body is in dynid_diagnose-inl.hpp.
#pragma once

#include <string>
#include <vector>

#include "dynid_dispatch.hpp"

namespace symoro::dynid {

struct DiagnoseOptions {
  std::string data, out, model, variant, apply, params;
  bool no_backlash = false;
  std::vector<std::string> train, heldout, only;  // empty: from the dataset's families
  int trial = 1;
  double interval_ms = 10, cutoff = 5, alpha = 1e-3, min_gain = 0.02, min_torque = 0.003;
};

struct DiagnoseCommand {
  using Options = DiagnoseOptions;
  template <class Full, class Model>
  static void run(const Common& common, const Options& o);
};

const CommandTable<DiagnoseOptions>& diagnose_units();  // generated: dynid_tables.cpp

}  // namespace symoro::dynid
