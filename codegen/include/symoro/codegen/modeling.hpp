// `symoroc model`: a robot's model files computed by the project itself from its description,
// so that OpenSYMORO is no longer needed. From a .par (modified DH geometry, standard inertial
// parameters): the base parameters (modeling/base_parameters.hpp says how), the inverse dynamics
// by Newton-Euler, the identification model (its derivatives along the base parameters), the
// Coriolis-gravity torques, the inertia matrix (derivatives along qdd), the direct dynamics
// (an LDL^T solve of M qdd = tau - h), the geometric model and the Jacobian of the last frame.
// The files are OpenSYMORO's format, so load_robot reads them like any other robot folder.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace symoro::codegen {

struct ModelFileText {
  std::string name;  // file name inside the robot folder: idm.txt, <robot>_base.par, ...
  std::string text;
};

struct Modeling {
  std::string robot;
  std::vector<ModelFileText> files;  // <robot>_base.par, regp, dim, idm, ccg, inm, ddm, fgm, jac
  std::vector<std::string> base_parameters;
  std::vector<std::string> notes;  // what the user should know (groupings found numerically)
};

struct ModelingOptions {
  // The frame of the geometric model and the Jacobian (fgm.txt, jac.txt); 0: the last one.
  // An arm with a gripper joint may want the wrist's (CRANE-X7: 7 of 8).
  int frame = 0;
  // URDF input only.
  std::string name;                      // the robot's name; default: the URDF's
  std::string base_link;                 // default: the root link
  std::string tip_link;                  // default: the end of the moving joints, when it is unique
  std::map<std::string, double> locked;  // off-chain moving joints' positions (default 0)
  bool rotor_inertia = true;             // each joint gets IA
  bool viscous = true;                   // ... FV
  bool coulomb = true;                   // ... FS
};

// "joint=position" (symoroc model --lock) into `options.locked`; throws std::invalid_argument
// naming the option and the value when it is no name and finite position within +-1000.
void add_lock(ModelingOptions& options, const std::string& spec);

// Errors name the file, line and column (grammar::ParseError, InputError).
Modeling model_from_par(const std::string& par_path, const ModelingOptions& options = {});

// The same from a .par's text (`path` names it in messages and gives the robot's default name).
Modeling model_from_par_text(const std::string& text, const std::string& path, const ModelingOptions& options = {});

// From a URDF: the files above plus <robot>.par and robot.yaml. Errors name the file and the
// link or joint (InputError).
Modeling model_from_urdf(const std::string& urdf_path, const ModelingOptions& options = {});

}  // namespace symoro::codegen
