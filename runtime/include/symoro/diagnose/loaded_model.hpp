// DiagnosisModel (diagnosis_model.hpp) of a robot model loaded at run time
// (symoro/robot/robot_library.hpp): the design stack through the library's regressors (the same
// stack_design as a generated model's, so the same numbers). The backlash stage simulates the
// robot's twin, compiled only for a robot linked into the program (diagnosis_model-inl.hpp passes
// it); without one it fails with a message, which the diagnosis reports as the stage's note.
#pragma once

#include <memory>

#include "symoro/diagnose/diagnosis_model.hpp"
#include "symoro/robot/model_handle.hpp"

namespace symoro::diagnose {

// The backlash stage's closed-loop fit on the robot's twin (DiagnosisModel::fit_backlash).
using BacklashFitter = BacklashFit (*)(const io::Log& measured, const trajectory::SampledReference& reference,
                                       const twin::TwinConfig& nominal, const BacklashFitOptions& options);

// model: the diagnosed model; full: its robot's full model (the library's first); backlash: the
// twin's fit, null for a robot that has none in this program.
std::shared_ptr<const DiagnosisModel> diagnosis_model(const robot::ModelHandle& model, const robot::ModelHandle& full,
                                                      BacklashFitter backlash = nullptr);

}  // namespace symoro::diagnose
