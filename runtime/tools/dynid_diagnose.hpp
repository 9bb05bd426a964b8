// dynid diagnose's options and its entry per model of each robot (any variant: --model), in
// generated units that only fetch the model's DiagnosisModel (symoro::<robot>_diagnosis); the
// diagnosis itself is symoro/diagnose/dataset_diagnosis.hpp's, compiled once.
#pragma once

#include <string>
#include <vector>

#include "dynid_dispatch.hpp"

namespace symoro::diagnose {
class DiagnosisModel;
}  // namespace symoro::diagnose

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

// The command on one model (dynid_diagnose.cpp).
void run_diagnose(const Common& common, const DiagnoseOptions& o, const diagnose::DiagnosisModel& model);

}  // namespace symoro::dynid
