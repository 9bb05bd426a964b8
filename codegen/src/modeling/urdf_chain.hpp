// A URDF's serial chain as a robot description: the chain from a base link to a tip link in
// Khalil-Kleinfinger modified DH (with the gamma, b generalization), its links' inertials as
// standard parameters in the DH frames (off-chain links merged exactly), and what robot.yaml
// records (limits, nominal parameters, the transforms between the URDF's frames and the DH ones).
#pragma once

#include <string>
#include <vector>

#include "symoro/codegen/modeling.hpp"

namespace symoro::codegen::modeling {

struct UrdfChain {
  std::string name;
  std::string par_text;    // <name>.par
  std::string robot_yaml;  // robot.yaml
  std::vector<std::string> notes;
};

// Errors name the file and the link or joint (InputError).
UrdfChain read_urdf_chain(const std::string& urdf_path, const ModelingOptions& options);

}  // namespace symoro::codegen::modeling
