// The backlash stage's simulation for a robot (diagnosis_model-inl.hpp's robot_backlash<Full>):
// the twin's closed loop, the heaviest template of the diagnosis, compiled once per robot
// (cmake/diagnosis_backlash.cpp.in) for all of its models.
#pragma once

#include "symoro/diagnose/backlash_fit.hpp"
#include "symoro/diagnose/diagnosis_model-inl.hpp"

namespace symoro::diagnose::detail {

template <class Full>
BacklashFit robot_backlash(const io::Log& measured, const trajectory::SampledReference& reference,
                           const twin::TwinConfig& nominal, const BacklashFitOptions& options) {
  return diagnose::fit_backlash<Full>(measured, reference, nominal, options);
}

}  // namespace symoro::diagnose::detail
