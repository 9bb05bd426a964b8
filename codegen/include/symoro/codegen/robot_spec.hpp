// robot.yaml: what the OpenSYMORO files do not say. Values of the geometric constants, joint
// names and limits, parameter units, the PD-audit domain, and the variants that fix some base
// parameters to constants at generation time (the rest are identified) and may add model-gap
// effects (effects.hpp).
#pragma once

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "symoro/codegen/effects.hpp"

namespace symoro::codegen {

// An error in a robot's input, located in a file ("file:line:column: error: message").
class InputError : public std::runtime_error {
 public:
  InputError(const std::string& file, int line, int column, const std::string& message);
};

struct JointSpec {
  std::string name;
  double lower = 0, upper = 0;              // rad or m
  double velocity = 0;                      // rad/s or m/s
  double effort = 0;                        // N m or N
  double audit_lower = 0, audit_upper = 0;  // the all-pose PD audit domain
};

struct VariantSpec {
  std::string name;
  std::string description;
  std::string base;  // the variant it starts from ('base:'), empty for none
  // Base parameter name patterns (`*` matches any run of characters) and their fixed values:
  // the base variant's (recursively) first, then the variant's own.
  std::vector<std::pair<std::string, double>> fixed;
  // Model-gap effects ('effects:'): the base variant's, then the variant's own; at most one
  // entry per effect and joint (or link).
  std::vector<EffectSpec> effects;
  int line = 0;  // in robot.yaml
};

struct RobotSpec {
  std::string path;  // robot.yaml
  std::string description;
  std::map<std::string, double> constants;
  std::vector<JointSpec> joints;
  // Units by parameter family (XX ... M, IA, FV, FS); prismatic joints use prismatic_units for
  // IA, FV and FS.
  std::map<std::string, std::string> units;
  std::map<std::string, std::string> prismatic_units;
  std::string identified = "full";  // the model identification uses: "full" or a variant
  std::vector<VariantSpec> variants;
  // Prior standard parameters by name (symoroc model writes the URDF's inertials here).
  std::map<std::string, double> nominal;
  // Where the robot came from when symoroc model read a URDF (robot.yaml `urdf`): the file, the
  // chain's ends and its joints' names there.
  struct Urdf {
    std::string file, base_link, tip_link;
    std::vector<std::string> joints;
  } urdf;
};

// Reads and validates robot.yaml. Angles may be written as "90 deg"; plain numbers are SI.
RobotSpec read_robot_spec(const std::string& path);

// True when `name` matches `pattern`, where `*` matches any run of characters.
bool glob_match(const std::string& pattern, const std::string& name);

}  // namespace symoro::codegen
