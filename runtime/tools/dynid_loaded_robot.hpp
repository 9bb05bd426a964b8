// A robot dynid was not built with: its folder's robot library (symoro/robot_abi.h), built into
// the robot cache on first use and loaded. The commands that run through a library (import,
// identify, diagnose, predict, compare, excite, export) take such a robot like a compiled one.
#pragma once

#include <memory>
#include <string>

#include "dynid_common.hpp"
#include "dynid_dispatch.hpp"
#include "symoro/identify/identification_model.hpp"
#include "symoro/robot/model_handle.hpp"

namespace symoro::dynid {

// compiled_robot (dynid_dispatch.hpp) says which robots take this path.
// The robot's model `label` ("full", a variant, "" robot.yaml's identified) from its library;
// building it prints one line on stderr. UsageError for a folder that is no robot, or a model it
// has not; the library's errors (a failed build, a missing compiler) as they are.
robot::ModelHandle loaded_model(const Common& common, const std::string& label);
std::shared_ptr<const identify::IdentificationModel> loaded_identification_model(const Common& common,
                                                                                 const std::string& label);

}  // namespace symoro::dynid
