// compiled_model<Model>() (compiled_model.hpp): the robot library's C ABI table of a generated
// model, under a handle with no library to keep loaded. The table's function, model_abi<Model>(),
// is only declared here (robot_abi_export.hpp): its definition, the model's kernels, is compiled
// once, by symoroc build, into the objects the program links (symoroc build --objects).
#pragma once

#include <cstddef>
#include <tuple>
#include <vector>

#include "symoro/robot/compiled_model.hpp"
#include "symoro/robot_abi_export.hpp"

namespace symoro::robot {

template <class Model>
const ModelHandle& compiled_model() {
  static const symoro_abi_model table = abi_export::model_abi<Model>();
  static const ModelHandle handle(Model::robot_name, &table);
  return handle;
}

// Instantiates compiled_model<M>() for model I of a robot's Models, and with Tail for every later
// one too (cmake/kernels.cpp.in).
using CompiledModelFactory = const ModelHandle& (*)();
template <class Models, std::size_t I, bool Tail>
void instantiate_compiled_models(std::vector<CompiledModelFactory>& out) {
  if constexpr (I < std::tuple_size_v<Models>) {
    out.push_back(&compiled_model<std::tuple_element_t<I, Models>>);
    if constexpr (Tail) instantiate_compiled_models<Models, I + 1, true>(out);
  }
}

}  // namespace symoro::robot
