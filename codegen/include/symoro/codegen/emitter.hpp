// C++ emission of a set of graph outputs as the body of a function templated on `Scalar`.
// Each node the outputs need is computed once (common subexpressions come from the graph's
// hash-consing, dead code is never reached); a node used once is written inline into its user.
#pragma once

#include <map>
#include <string>
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

// A double as a C++ literal that reads back to the same value ("0.25", "2.0", "1e-05").
std::string cpp_literal(double v);

}  // namespace symoro::codegen
