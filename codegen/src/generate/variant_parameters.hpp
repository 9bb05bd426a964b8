// What a robot.yaml variant makes of the robot's model (variant_parameters.cpp). Errors are
// InputErrors at the variant's line in robot.yaml.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "symoro/codegen/effects.hpp"
#include "symoro/codegen/robot_model.hpp"

namespace symoro::codegen::generate {

// The base parameters the variant fixes, with their values, in parameter order.
std::vector<std::pair<std::string, double>> resolve_fixed(const RobotModel& r, const VariantSpec& v);

// The effect parameters the variant adds, named apart from every name of the model.
std::vector<EffectParameter> resolve_effects(const RobotModel& r, const VariantSpec& v);

}  // namespace symoro::codegen::generate
