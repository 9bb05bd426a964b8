#include "symoro/codegen/passes.hpp"

#include <algorithm>
#include <set>
#include <stdexcept>
#include <unordered_map>

namespace symoro::codegen {

std::vector<NodeId> reachable(const ExprGraph& g, const std::vector<NodeId>& roots) {
  std::vector<char> seen(g.size(), 0);
  std::vector<NodeId> stack(roots.begin(), roots.end());
  while (!stack.empty()) {
    const NodeId id = stack.back();
    stack.pop_back();
    if (seen[id]) continue;
    seen[id] = 1;
    const Node& n = g.node(id);
    if (n.a >= 0) stack.push_back(n.a);
    if (n.b >= 0) stack.push_back(n.b);
  }
  std::vector<NodeId> order;
  for (std::size_t i = 0; i < seen.size(); ++i)
    if (seen[i]) order.push_back(static_cast<NodeId>(i));
  return order;
}

// Rebuilds node `n` from new children through the folding constructors.
static NodeId rebuild(ExprGraph& g, const Node& n, NodeId a, NodeId b) {
  switch (n.op) {
    case Op::Add:
      return g.add(a, b);
    case Op::Sub:
      return g.sub(a, b);
    case Op::Mul:
      return g.mul(a, b);
    case Op::Div:
      return g.div(a, b);
    case Op::Neg:
      return g.neg(a);
    case Op::Pow:
      return g.pow(a, n.value);
    case Op::Sin:
      return g.sin(a);
    case Op::Cos:
      return g.cos(a);
    case Op::Sign:
      return g.sign(a);
    case Op::Exp:
      return g.exp(a);
    case Op::Tanh:
      return g.tanh(a);
    case Op::Constant:
    case Op::Symbol:
      break;
  }
  throw std::logic_error("rebuild of a leaf");
}

std::vector<NodeId> substitute(ExprGraph& g, const std::vector<NodeId>& roots,
                               const std::map<std::string, NodeId>& replacements) {
  std::unordered_map<NodeId, NodeId> map;
  for (NodeId id : reachable(g, roots)) {
    const Node n = g.node(id);  // copy: the graph grows below
    NodeId out = id;
    if (n.op == Op::Symbol) {
      auto it = replacements.find(g.symbol_name(n.symbol));
      if (it != replacements.end()) out = it->second;
    } else if (n.op != Op::Constant) {
      const NodeId a = map.at(n.a);
      const NodeId b = n.b >= 0 ? map.at(n.b) : -1;
      if (a != n.a || b != n.b) out = rebuild(g, n, a, b);
    }
    map.emplace(id, out);
  }
  std::vector<NodeId> result;
  result.reserve(roots.size());
  for (NodeId r : roots) result.push_back(map.at(r));
  return result;
}

std::vector<NodeId> differentiate(ExprGraph& g, const std::vector<NodeId>& roots, const std::string& symbol) {
  std::unordered_map<NodeId, NodeId> d;  // node -> its derivative
  for (NodeId id : reachable(g, roots)) {
    const Node n = g.node(id);
    NodeId out = g.zero();
    switch (n.op) {
      case Op::Constant:
        break;
      case Op::Symbol:
        out = g.symbol_name(n.symbol) == symbol ? g.one() : g.zero();
        break;
      case Op::Add:
        out = g.add(d.at(n.a), d.at(n.b));
        break;
      case Op::Sub:
        out = g.sub(d.at(n.a), d.at(n.b));
        break;
      case Op::Mul:
        out = g.add(g.mul(d.at(n.a), n.b), g.mul(n.a, d.at(n.b)));
        break;
      case Op::Div:  // (a/b)' = (a' - (a/b) b') / b, reusing the quotient itself
        out = g.div(g.sub(d.at(n.a), g.mul(id, d.at(n.b))), n.b);
        break;
      case Op::Neg:
        out = g.neg(d.at(n.a));
        break;
      case Op::Pow:
        out = g.mul(g.mul(g.constant(n.value), g.pow(n.a, n.value - 1.0)), d.at(n.a));
        break;
      case Op::Sin:
        out = g.mul(g.cos(n.a), d.at(n.a));
        break;
      case Op::Cos:
        out = g.neg(g.mul(g.sin(n.a), d.at(n.a)));
        break;
      case Op::Sign:
        break;
      case Op::Exp:
        out = g.mul(id, d.at(n.a));
        break;        // exp(a)' = exp(a) a', reusing the node
      case Op::Tanh:  // tanh(a)' = (1 - tanh(a)^2) a', reusing the node
        out = g.mul(g.sub(g.one(), g.pow(id, 2.0)), d.at(n.a));
        break;
    }
    d.emplace(id, out);
  }
  std::vector<NodeId> result;
  result.reserve(roots.size());
  for (NodeId r : roots) result.push_back(d.at(r));
  return result;
}

std::vector<std::string> free_symbols(const ExprGraph& g, const std::vector<NodeId>& roots) {
  std::set<std::string> names;
  for (NodeId id : reachable(g, roots))
    if (g.node(id).op == Op::Symbol) names.insert(g.symbol_name(g.node(id).symbol));
  return {names.begin(), names.end()};
}

OperationCount count_operations(const ExprGraph& g, const std::vector<NodeId>& roots) {
  OperationCount c;
  for (NodeId id : reachable(g, roots)) {
    switch (g.node(id).op) {
      case Op::Add:
      case Op::Sub:
        ++c.add;
        break;
      case Op::Mul:
        ++c.mul;
        break;
      case Op::Div:
        ++c.div;
        break;
      case Op::Neg:
        ++c.neg;
        break;
      case Op::Pow:
        ++c.pow;
        break;
      case Op::Sin:
      case Op::Cos:
        ++c.trig;
        break;
      case Op::Sign:
        ++c.sign;
        break;
      case Op::Exp:
      case Op::Tanh:
        ++c.exp;
        break;
      case Op::Constant:
      case Op::Symbol:
        break;
    }
  }
  return c;
}

}  // namespace symoro::codegen
