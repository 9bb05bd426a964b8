// A generated Model linked into the program, as the same ModelHandle a loaded robot library gives
// (model_handle.hpp): the runtime compiled once reaches a shipped robot and a loaded one through
// one interface. Declared here, defined in compiled_model-inl.hpp and compiled once per model into
// symoro::<robot>_abi (cmake/SymoroRobots.cmake: the model's kernels, as its robot library holds
// them): link that library, or include the -inl header to compile a model here.
#pragma once

#include "symoro/robot/model_handle.hpp"

namespace symoro::robot {

// The model's handle (static storage; its functions the robot library's C ABI kernels).
template <class Model>
const ModelHandle& compiled_model();

}  // namespace symoro::robot
