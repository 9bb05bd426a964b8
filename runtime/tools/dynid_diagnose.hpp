// dynid diagnose's options and its body on any model of any robot (--model): the model's
// DiagnosisModel (symoro/diagnose/loaded_model.hpp) under symoro/diagnose/dataset_diagnosis.hpp.
#pragma once

#include <string>
#include <vector>

#include "dynid_common.hpp"

namespace symoro::diagnose {
class DiagnosisModel;
}  // namespace symoro::diagnose

namespace symoro::dynid {

struct DiagnoseOptions {
  std::string data, out, model, variant, apply, params;
  bool no_backlash = false;
  std::vector<std::string> train, heldout, only;  // empty: from the dataset's families
  // Defaults: diagnose::DatasetDiagnosisOptions' (set where the command is added).
  int trial = 0;
  double interval_ms = 0, cutoff = 0, alpha = 0, min_gain = 0, min_torque = 0;
};

// The command on one model (dynid_diagnose.cpp).
void run_diagnose(const Common& common, const DiagnoseOptions& options, const diagnose::DiagnosisModel& model);

}  // namespace symoro::dynid
