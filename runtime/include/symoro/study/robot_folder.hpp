// What a study takes from a robot folder besides the compiled model: the controller description
// (controller.yaml: CLIE and the closed-loop validation) and the trajectory design (references
// for logs without them), and robot.yaml's nominal standard parameters (the physical rescue's
// default prior). dynid identify and the Python package read them here, the same way.
#pragma once

#include <filesystem>
#include <vector>

#include "symoro/identify/identification_model.hpp"
#include "symoro/study/study.hpp"

namespace symoro::study {

// The closed loop from <robot_dir>/controller.yaml and the design (`design`, or
// <robot_dir>/trajectories.yaml when empty); either may be absent (ClosedLoopSource::why says
// what is missing). DataError on a malformed file.
ClosedLoopSource closed_loop_source(const std::filesystem::path& robot_dir, const identify::ModelDescription& model,
                                    const std::filesystem::path& design = {});

// robot.yaml's `nominal:` standard parameters (symoroc model writes a URDF's there) in the order
// of `standard`, a variant's effect parameters 0; false when robot.yaml has none. DataError
// naming robot.yaml when it is malformed or lacks a rigid-body parameter.
bool nominal_standard_parameters(const std::filesystem::path& robot_dir,
                                 const std::vector<StandardParameterInfo>& standard, std::vector<double>& values);

}  // namespace symoro::study
