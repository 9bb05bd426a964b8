// dynid diagnose's unit body for one model (included by the generated units only): the model's
// DiagnosisModel, compiled in symoro::<robot>_diagnosis, handed to run_diagnose.
#pragma once

#include "dynid_diagnose.hpp"
#include "symoro/diagnose/diagnosis_model.hpp"

namespace symoro::dynid {

template <class Full, class Model>
void DiagnoseCommand::run(const Common& common, const DiagnoseOptions& o) {
  run_diagnose(common, o, *diagnose::diagnosis_model<Full, Model>());
}

}  // namespace symoro::dynid
