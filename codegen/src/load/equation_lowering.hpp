// A model file's equations as nodes of the expression graph: each equation's right-hand side,
// over the earlier equations, the file's inputs and robot.yaml's constants.
#pragma once

#include <map>
#include <set>
#include <string>

#include "symoro/codegen/expr_graph.hpp"
#include "symoro/grammar/ast.hpp"

namespace symoro::codegen::load {

class EquationLowering {
 public:
  // The constants (and pi) become graph constants once, here.
  EquationLowering(ExprGraph& g, const std::map<std::string, double>& constants);

  // Runs the file's equations. `inputs` are the symbols it may use besides earlier equations;
  // `role` says what the file computes, for messages. Returns name -> node after the last line.
  std::map<std::string, NodeId> run(const grammar::ModelFile& file, const std::set<std::string>& inputs,
                                    const std::string& role);

 private:
  NodeId leaf(const grammar::Expr& e, const std::map<std::string, NodeId>& env, const std::set<std::string>& inputs,
              const std::string& path, const std::string& role);
  NodeId lower(const grammar::Expr& root, const std::map<std::string, NodeId>& env, const std::set<std::string>& inputs,
               const std::string& path, const std::string& role);

  ExprGraph& g_;
  std::map<std::string, NodeId> constants_;
};

}  // namespace symoro::codegen::load
