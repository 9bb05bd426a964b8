// DiagnosisModel (diagnosis_model.hpp) for a generated model: the runtime's one implementation
// (loaded_model.hpp) over the model's handle (its kernels in symoro::<robot>_identification), the
// backlash stage's twin on the full model's. Compiled into symoro::<robot>_diagnosis
// (cmake/SymoroRobots.cmake); include it only to instantiate a model that has no such library.
#pragma once

#include <cstddef>
#include <memory>
#include <tuple>
#include <vector>

#include "symoro/diagnose/diagnosis_model.hpp"
#include "symoro/diagnose/loaded_model.hpp"
#include "symoro/robot/compiled_model.hpp"

namespace symoro::diagnose {
template <class Full, class Model>
std::shared_ptr<const DiagnosisModel> diagnosis_model() {
  static const std::shared_ptr<const DiagnosisModel> model =
      diagnosis_model(robot::compiled_model<Model>(), robot::compiled_model<Full>());
  return model;
}

namespace detail {

// Instantiates diagnosis_model<Full, M>() for model I of a robot's Models, and with Tail for
// every later one too (cmake/diagnosis.cpp.in: one unit per robot).
using DiagnosisModelFactory = std::shared_ptr<const DiagnosisModel> (*)();
template <class Full, class Models, std::size_t I, bool Tail>
void instantiate_diagnosis_models(std::vector<DiagnosisModelFactory>& out) {
  if constexpr (I < std::tuple_size_v<Models>) {
    out.push_back(&diagnosis_model<Full, std::tuple_element_t<I, Models>>);
    if constexpr (Tail) instantiate_diagnosis_models<Full, Models, I + 1, true>(out);
  }
}

}  // namespace detail
}  // namespace symoro::diagnose
