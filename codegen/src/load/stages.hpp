// load_robot's three stages, in the order it runs them: read the folder's files (syntax), check
// the .par and the DIM's tables against each other and robot.yaml (meaning), and lower the model
// files' equations into the expression graph. Each stage fills its part of the RobotModel; every
// error of a stage comes before any of the next, as when they were one function.
#pragma once

#include <set>
#include <string>

#include "symoro/codegen/robot_model.hpp"
#include "symoro/grammar/ast.hpp"

namespace symoro::codegen::load {

// The parsed files of a robot folder. robot.yaml is already in RobotModel::spec; the base .par
// is only checked for syntax (the model files carry its content).
struct RobotFiles {
  std::string par_path;  // <robot>.par, as found in the folder (errors name it)
  grammar::ParFile par;
  grammar::ModelFile dim, idm, ddm, inm, ccg, fgm, jac, regp;
};

// The symbols the check stage found parameters, which the lowering stage takes as inputs.
struct ParameterNames {
  std::set<std::string> standard;  // the .par's symbolic inertial and joint parameters
  std::set<std::string> base;      // the symbolic cells of the DIM's parameter tables
};

// Stage 1: the folder's name, robot.yaml, the .par files and the model files, parsed; fills
// name, dir, spec and sources.
RobotFiles read_robot_folder(const std::string& dir, RobotModel& m);

// Stage 2: the .par's structure, frames, joint symbols and gravity, the standard parameters and
// the base parameters of the DIM's tables, checked against robot.yaml; fills n, frames, q, qd,
// qdd, tau, gravity, standard and base.
ParameterNames check_robot(const RobotFiles& files, RobotModel& m);

// Stage 3: every model file's equations into m.graph, and their outputs (dim, idm, ccg, ddm,
// inm, fgm, jac, base_from_standard) picked by name.
void lower_robot(const RobotFiles& files, const ParameterNames& names, RobotModel& m);

// An InputError at a parsed position of `file`.
[[noreturn]] inline void fail_at(const std::string& file, const grammar::Position& at, const std::string& message) {
  throw InputError(file, at.line, at.column, message);
}

}  // namespace symoro::codegen::load
