// Passes over the expression graph. Each works on a set of roots and returns new roots in the
// same graph; hash-consing makes the result share every unchanged subexpression.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "symoro/codegen/expr_graph.hpp"

namespace symoro::codegen {

// Specialization: replaces symbols by other nodes (constants, to fix parameters or inputs such
// as FS = 0 or QP = 0) and refolds everything above them.
std::vector<NodeId> substitute(ExprGraph& g, const std::vector<NodeId>& roots,
                               const std::map<std::string, NodeId>& replacements);

// Symbolic differentiation of every root with respect to one symbol (d sign / dx = 0,
// d exp(a) / dx = exp(a) da / dx, d tanh(a) / dx = (1 - tanh(a)^2) da / dx).
std::vector<NodeId> differentiate(ExprGraph& g, const std::vector<NodeId>& roots, const std::string& symbol);

// Dead-code elimination: the nodes the roots need, in increasing id (topological) order.
std::vector<NodeId> reachable(const ExprGraph& g, const std::vector<NodeId>& roots);

// The symbols the roots depend on, sorted by name.
std::vector<std::string> free_symbols(const ExprGraph& g, const std::vector<NodeId>& roots);

// Operation counts of the code that evaluates the roots once (each shared node counted once).
struct OperationCount {
  int add = 0;  // additions and subtractions
  int mul = 0;
  int div = 0;
  int neg = 0;
  int pow = 0;   // x**k, emitted as k-1 multiplications for small integers
  int trig = 0;  // sin and cos
  int sign = 0;
  int exp = 0;  // exp and tanh
  int total() const { return add + mul + div + neg + pow + trig + sign + exp; }
};
OperationCount count_operations(const ExprGraph& g, const std::vector<NodeId>& roots);

}  // namespace symoro::codegen
