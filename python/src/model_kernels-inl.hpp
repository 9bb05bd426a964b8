// model_kernels<Full, Model>(): a generated model linked into the module, as ModelKernels: the
// batch loops written once over a model handle (loaded_kernels.cpp), here the model's linked
// kernels (symoro/robot/compiled_model.hpp, compiled into symoro::<robot>_identification), so the
// module compiles nothing per model; its identification and diagnosis interfaces the robot's
// libraries' (the diagnosis with the twin's backlash stage). Included by the per-robot-model units
// CMake writes from robot_unit.cpp.in.
#pragma once

#include <cstddef>
#include <tuple>
#include <vector>

#include "model_kernels.hpp"
#include "symoro/diagnose/diagnosis_model.hpp"
#include "symoro/identify/identification_model.hpp"
#include "symoro/robot/compiled_model.hpp"

namespace symoro::python {

template <class Full, class Model>
ModelKernels model_kernels() {
  ModelKernels k = handle_kernels(robot::compiled_model<Model>());
  k.identification = &identify::identification_model<Model>;
  k.diagnosis = &diagnose::diagnosis_model<Full, Model>;
  return k;
}

// Model I of the tuple Models of the robot whose full model is Full (and, when Tail, every
// later one).
template <class Full, class Models, std::size_t I, bool Tail>
void add_model_kernels(std::vector<ModelKernels>& out) {
  if constexpr (I < std::tuple_size_v<Models>) {
    out.push_back(model_kernels<Full, std::tuple_element_t<I, Models>>());
    if constexpr (Tail) add_model_kernels<Full, Models, I + 1, true>(out);
  }
}

}  // namespace symoro::python
