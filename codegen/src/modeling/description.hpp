// A robot as `symoroc model` reads it: the modified Denavit-Hartenberg geometry (Khalil and
// Kleinfinger) and the standard inertial parameters of a .par file, lowered into an expression
// graph. Geometric constants stay symbols (D3, L1, G3: the model files keep their names, and
// robot.yaml gives their values); angles that are multiples of pi/2 get exact sines and cosines.
#pragma once

#include <array>
#include <map>
#include <string>
#include <vector>

#include "symoro/codegen/expr_graph.hpp"
#include "symoro/grammar/ast.hpp"

namespace symoro::codegen::modeling {

// Inertial parameter families of a link, in table order.
inline const std::array<const char*, 10> kInertialFamilies = {"XX", "XY", "XZ", "YY", "YZ",
                                                              "ZZ", "MX", "MY", "MZ", "M"};
enum Inertial { XX, XY, XZ, YY, YZ, ZZ, MX, MY, MZ, M };

// One link's parameters as graph nodes (a symbol or 0): the ten inertial ones, then the rotor
// inertia and the viscous and Coulomb friction of its joint.
struct LinkParameters {
  std::array<NodeId, 10> inertial{};
  NodeId ia = 0, fv = 0, fs = 0;
};

struct JointDescription {
  int ant = 0;    // the antecedent frame, 0 = base
  int sigma = 0;  // 0 revolute, 1 prismatic
  int mu = 1;
  // The .par's expressions, for the tables of the model files.
  grammar::Expr gamma, b, alpha, d, theta, r;
  // The same as graph nodes (the joint variable a symbol).
  NodeId gamma_n = 0, b_n = 0, alpha_n = 0, d_n = 0, theta_n = 0, r_n = 0;
  std::string q, qd, qdd, tau;  // symbol names: th1 or r3, QP1, QDP1, GAM1
};

struct Description {
  std::string name;  // the robot's name (the .par's, else its file name)
  std::string path;
  int n = 0;
  std::vector<JointDescription> joints;
  std::vector<LinkParameters> links;        // the standard parameters
  std::vector<grammar::Expr> gravity_expr;  // G, 3 entries
  std::array<NodeId, 3> gravity{};
  std::vector<std::string> geometric_symbols;  // every symbol of the geometry and of G
  std::vector<std::string> standard;           // standard parameter names, link by link
};

// Reads a .par; errors name the file, line and column (InputError).
Description read_description(ExprGraph& g, const grammar::ParFile& par);

// Lowers a .par expression: numbers fold, `pi` is a constant, other symbols stay symbols.
NodeId lower(ExprGraph& g, const grammar::Expr& e);

// Sine and cosine that are exact (0, 1, -1) at constant multiples of pi/2.
NodeId exact_sin(ExprGraph& g, NodeId a);
NodeId exact_cos(ExprGraph& g, NodeId a);

// A .par expression as text (the tables of the model files).
std::string to_text(const grammar::Expr& e);

}  // namespace symoro::codegen::modeling
