// DiagnosisModel (diagnosis_model.hpp) of a robot model loaded at run time
// (symoro/robot/robot_library.hpp): the design stack through the library's regressors (the same
// stack_design as a generated model's, so the same numbers), and the backlash stage's twin on
// the full model's handle.
#pragma once

#include <memory>

#include "symoro/diagnose/diagnosis_model.hpp"
#include "symoro/robot/model_handle.hpp"

namespace symoro::diagnose {

// model: the diagnosed model; full: its robot's full model (the library's first).
std::shared_ptr<const DiagnosisModel> diagnosis_model(const robot::ModelHandle& model, const robot::ModelHandle& full);

}  // namespace symoro::diagnose
