// C++ emission of a set of graph outputs as the body of a function templated on `Scalar`.
// Each node the outputs need is computed once (common subexpressions come from the graph's
// hash-consing, dead code is never reached); a node used once is written inline into its user.
#pragma once

#include <map>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "symoro/codegen/expr_graph.hpp"

namespace symoro::codegen {

struct Assignment {
  std::string target;  // an lvalue, e.g. "W(0, 3)"
  NodeId value;
};

// `inputs` maps each graph symbol the outputs may use to the C++ expression that reads it (for
// example "th1" -> "q[0]"). Constant outputs are written as Scalar(value). Output lines are
// indented by `indent`. Throws std::logic_error naming a symbol with no input.
std::string emit_body(const ExprGraph& g, const std::map<std::string, std::string>& inputs,
                      const std::vector<Assignment>& outputs, const std::string& indent);

// The same in stages, for a function that runs code of its own between them (a factorization
// whose result later expressions read as inputs): every stage's outputs are passed to the
// constructor so that a node a later stage uses is kept in a local, and emit() writes one stage:
// the nodes it needs that no earlier stage computed, then its assignments.
class BodyEmitter {
 public:
  BodyEmitter(const ExprGraph& g, std::map<std::string, std::string> inputs, const std::vector<NodeId>& all_roots,
              std::string indent);
  std::string emit(const std::vector<Assignment>& outputs);

  // Operator precedence of an emitted operand, to place parentheses only where needed.
  enum Prec { kSum = 1, kProduct = 2, kUnary = 3, kAtom = 4 };
  struct Text {
    std::string s;
    int prec = kAtom;
  };

 private:
  const ExprGraph& g_;
  std::map<std::string, std::string> inputs_;
  std::string indent_;
  std::unordered_map<NodeId, int> uses_;
  std::unordered_set<NodeId> pow_operand_;
  std::unordered_map<NodeId, Text> text_;
  int temps_ = 0;
};

// The `using` declarations of a function body that evaluates `roots` (std::exp and std::tanh
// only where the body needs them, so models without effects read as before).
std::string math_usings(const ExprGraph& g, const std::vector<NodeId>& roots);

// A double as a C++ literal that reads back to the same value ("0.25", "2.0", "1e-05").
std::string cpp_literal(double v);

}  // namespace symoro::codegen
