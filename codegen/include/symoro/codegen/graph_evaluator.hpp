// Numeric values of some roots of an expression graph, for given values of its symbols: what
// `symoroc model` uses to find the particular cases of the base parameters, and what the tests
// use to compare two models.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "symoro/codegen/expr_graph.hpp"

namespace symoro::codegen {

class Evaluator {
 public:
  Evaluator(const ExprGraph& g, std::vector<NodeId> roots);
  // Absent symbols are 0.
  std::vector<double> operator()(const std::map<std::string, double>& symbols);

 private:
  const ExprGraph& g_;
  std::vector<NodeId> roots_, order_;
  std::vector<double> v_;
};

}  // namespace symoro::codegen
