// The robots dynid reaches, as robot::ModelHandles: a robot it was built with (linked in: its
// kernels in symoro::<robot>_identification, listed by the generated dynid_tables.cpp) and any
// other robot folder, through its robot library (symoro/robot_abi.h), built into the robot cache
// on first use and loaded. Every command is compiled once and runs on both alike.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dynid_common.hpp"
#include "symoro/identify/identification_model.hpp"
#include "symoro/robot/compiled_model.hpp"
#include "symoro/robot/model_handle.hpp"
#include "symoro/trajectory/design.hpp"

namespace symoro::dynid {

// The robots of robots/ this dynid was built with, in folder order (generated).
const std::vector<std::string>& robot_names();

// A robot this dynid was built with, its models linked in; null for another name (generated).
const robot::LinkedRobot* linked_robot(const std::string& robot);

// The files a robot's code was generated from, with their digests (generated/<robot>/source.hpp,
// gathered in the generated dynid_tables.cpp).
struct SourceFile {
  const char* name;
  const char* digest;
};
std::vector<SourceFile> robot_sources(const std::string& robot);

// Refuses (UsageError) a robot folder (--robots-dir/<robot>) whose robot.yaml or model files
// differ from those this dynid was compiled from: the compiled copy would be used silently.
void check_robot_folder(const Common& common);

// Whether common.robot is one this dynid was compiled with, from the folder it was compiled from
// (a --robot folder elsewhere is loaded from its library, even under a compiled robot's name).
bool compiled_robot(const Common& common);

// Model `label` of common.robot ("full", a robot.yaml variant, "" robot.yaml's `identified`):
// linked in (compiled_robot; the folder checked by check_robot_folder), else from its library,
// whose build prints one line on stderr. UsageError for a folder that is no robot or a model it
// has not; the library's errors (a failed build, a missing compiler) as they are.
robot::ModelHandle robot_model(const Common& common, const std::string& label);

// The robot's full model (the twin's plant, a variant's parent).
inline robot::ModelHandle full_model(const Common& common) { return robot_model(common, "full"); }

// The IdentificationModel of model `label` (identify::identification_model over its handle and
// its robot's full model's).
std::shared_ptr<const identify::IdentificationModel> identification_model(const Common& common,
                                                                          const std::string& label);

// The model a --params argument is for: a parameters file's `model:` ("full" when it names
// none; --model, when given, must agree), or `model` itself for `nominal`. UsageError naming the
// file when it is missing or no YAML.
std::string parameters_model(const std::string& params, const std::string& model);

// phi of `model` from --params: a study's report/parameters.yaml (its integrity checked, a warning
// when edited), or `nominal`: robot.yaml's nominal standard parameters (symoroc model writes a
// URDF's there), UsageError when it has none.
Eigen::VectorXd parameters_phi(const Common& common, const robot::ModelHandle& model, const std::string& params);

// The logged torque's delay a fit on top of --params takes (ms), and why: the one given (with a
// warning on stderr, as parameters_phi's, when the parameters file says the arm was identified at
// another), else the file's torque_delay_ms (the arm's identification's: its rotor inertias carry
// that timing), else 0 (nominal parameters, or a file from before the key).
struct FitTiming {
  double torque_delay_ms = 0;
  std::string why;
};
FitTiming fit_torque_delay(const std::string& params, std::optional<double> given_ms);

// The trajectory design the command reads (Common::design_path) for these joints; a robot folder
// without one gets a UsageError saying how to make one (dynid excite).
trajectory::TrajectoryDesign read_design(const Common& common, const std::vector<JointInfo>& joints);

}  // namespace symoro::dynid
