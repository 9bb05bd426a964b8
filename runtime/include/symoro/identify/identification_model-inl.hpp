// identification_model<Model>() (identification_model.hpp) for a generated Model: the
// IdentificationModel compiled once for every robot (loaded_model.hpp) over the model's handle
// (symoro/robot/compiled_model.hpp), the same code a robot loaded at run time goes through. Per
// model only the generated kernels compile, in units of their own (symoro::<robot>_identification,
// cmake/SymoroRobots.cmake); for a model with no such library, also include
// symoro/robot/compiled_model-inl.hpp and symoro/robot_abi_second_derivatives-inl.hpp.
#pragma once

#include <cstddef>
#include <memory>
#include <tuple>
#include <vector>

#include "symoro/identify/identification_model.hpp"
#include "symoro/identify/loaded_model.hpp"
#include "symoro/robot/compiled_model.hpp"

namespace symoro::identify {

template <class Model>
std::shared_ptr<const IdentificationModel> identification_model() {
  static const std::shared_ptr<const IdentificationModel> model =
      identification_model(robot::compiled_model<Model>(), robot::compiled_model<typename Model::Parent>());
  return model;
}

namespace detail {

// Instantiates identification_model<M>() for model I of a robot's Models, and with Tail for every
// later one too (cmake/identification.cpp.in: one unit per robot). Each
// function's address goes to `out`, so that the unit emits its definition for the linker.
using IdentificationModelFactory = std::shared_ptr<const IdentificationModel> (*)();
template <class Models, std::size_t I, bool Tail>
void instantiate_identification_models(std::vector<IdentificationModelFactory>& out) {
  if constexpr (I < std::tuple_size_v<Models>) {
    out.push_back(&identification_model<std::tuple_element_t<I, Models>>);
    if constexpr (Tail) instantiate_identification_models<Models, I + 1, true>(out);
  }
}

}  // namespace detail

}  // namespace symoro::identify
