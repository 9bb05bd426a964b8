// A robot as the compiler sees it: the OpenSYMORO files of robots/<name>/ read, checked against
// each other and robot.yaml, and lowered into one expression graph. Symbols in the graph keep
// their OpenSYMORO names (th1, QP1, QDP1, GAM1, ZZR1, XX2, ...); geometric constants are
// already replaced by their values.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "symoro/codegen/expr_graph.hpp"
#include "symoro/codegen/robot_spec.hpp"
#include "symoro/grammar/ast.hpp"

namespace symoro::codegen {

// Parameter families in table order; the last three are per joint.
inline const std::vector<std::string> kFamilies = {"XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX",
                                                   "MY", "MZ", "M",  "IA", "FV", "FS"};

struct ParameterRef {
  std::string name;
  std::string family;
  int joint = 0;  // 1-based
  std::string unit;
};

struct Frame {
  int ant = 0, sigma = 0, mu = 0;
  double gamma = 0, b = 0, alpha = 0, d = 0, theta = 0, r = 0;
};

struct RobotModel {
  std::string name;  // the folder name
  std::string dir;
  RobotSpec spec;
  int n = 0;  // joints

  std::vector<Frame> frames;
  double gravity[3] = {0, 0, 0};
  std::vector<std::string> q, qd, qdd, tau;  // symbol names per joint

  std::vector<ParameterRef> base;      // all base parameters, in canonical order
  std::vector<ParameterRef> standard;  // symbolic standard parameters of the .par

  ExprGraph graph;
  // Outputs, as nodes of `graph`:
  std::vector<std::vector<NodeId>> dim;  // [joint][base parameter]: DG entries
  std::vector<NodeId> idm;               // GAM per joint
  std::vector<NodeId> ccg;               // GAM per joint with QDP = 0
  std::vector<NodeId> ddm;               // QDP per joint
  std::vector<std::vector<NodeId>> inm;  // A[i][j], full symmetric
  std::vector<std::vector<NodeId>> fgm;  // 4 x 4
  int fgm_frame = 0;
  std::vector<std::vector<NodeId>> jac;    // 6 x n
  std::vector<NodeId> base_from_standard;  // per base parameter, over standard symbols

  // The files of the folder the model was read from, with their content digests (file name,
  // XXH3-128 hex): generated into source.hpp, so that the runtime can tell a robot folder edited
  // after it was compiled (source_digest.hpp).
  std::vector<std::pair<std::string, std::string>> sources;
};

// Reads robots/<name>/ (robot.yaml and the OpenSYMORO files). Errors name the file, line and
// column: grammar::ParseError for syntax, InputError for meaning.
RobotModel load_robot(const std::string& dir);

}  // namespace symoro::codegen
