// A generated Model linked into the program, as the same ModelHandle a loaded robot library gives
// (model_handle.hpp): the runtime compiled once reaches a shipped robot and a loaded one through
// one interface. Declared here, defined in compiled_model-inl.hpp over the model's C ABI table,
// whose kernels are the objects of the robot's own library (symoroc build --objects): link
// symoro::<robot>_identification (cmake/SymoroRobots.cmake), which holds both.
#pragma once

#include <tuple>
#include <type_traits>
#include <vector>

#include "symoro/robot/model_handle.hpp"

namespace symoro::robot {

// The model's handle (static storage; its functions the robot library's C ABI kernels).
template <class Model>
const ModelHandle& compiled_model();

// A robot linked into the program: its models' handles (the full model first, then its variants
// as robot.yaml lists them) and the index of robot.yaml's `identified` one. Each robot's library
// symoro::<robot>_identification defines `const LinkedRobot& symoro::robot::linked::<robot>()`
// (cmake/identification.cpp.in), so that a program compiled once (dynid) can list its linked
// robots without including their headers.
struct LinkedRobot {
  std::vector<const ModelHandle*> models;
  int identified = 0;
};

// A robot's Models (a std::tuple of its generated model types) as linked handles.
template <class Models>
struct LinkedModels;
template <class... Model>
struct LinkedModels<std::tuple<Model...>> {
  template <class Identified>
  static LinkedRobot robot() {
    LinkedRobot r;
    r.models = {&compiled_model<Model>()...};
    int index = 0;
    ((r.identified = std::is_same_v<Model, Identified> ? index : r.identified, ++index), ...);
    return r;
  }
};

template <class Models, class Identified>
LinkedRobot linked_robot() {
  return LinkedModels<Models>::template robot<Identified>();
}

}  // namespace symoro::robot
