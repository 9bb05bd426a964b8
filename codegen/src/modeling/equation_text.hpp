// Graph nodes as the compiler's input text: `NAME = expression;` lines in OpenSYMORO's syntax
// (+ - * / **, sin, cos, sign), each later line free to use earlier names.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "symoro/codegen/expr_graph.hpp"

namespace symoro::codegen::modeling {

// The shortest decimal text that reads back to the same double.
std::string number_text(double v);

// One expression, inline; nodes in `names` print as their name.
std::string expression_text(const ExprGraph& g, NodeId root, const std::map<NodeId, std::string>& names);

// The equations computing `outputs` (name, node), in order: sines and cosines of the joint
// variables first (C1 = cos(th1); S1 = sin(th1), OpenSYMORO's names), then every node that more
// than one expression uses, once, as a temporary `<prefix><k>`, then the outputs. `joints` are the
// joint variables' names, in joint order.
std::string equations_text(const ExprGraph& g, const std::vector<std::pair<std::string, NodeId>>& outputs,
                           const std::vector<std::string>& joints, const std::string& prefix);

}  // namespace symoro::codegen::modeling
