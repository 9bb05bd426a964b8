#include "symoro/codegen/graph_evaluator.hpp"

#include <cmath>
#include <utility>

#include "symoro/codegen/passes.hpp"

namespace symoro::codegen {

Evaluator::Evaluator(const ExprGraph& g, std::vector<NodeId> roots)
    : g_(g), roots_(std::move(roots)), order_(reachable(g, roots_)), v_(g.size(), 0.0) {}

std::vector<double> Evaluator::operator()(const std::map<std::string, double>& symbols) {
  const ExprGraph& g = g_;
  std::vector<double>& v = v_;
  for (const NodeId id : order_) {
    const Node& n = g.node(id);
    const double a = n.a >= 0 ? v[n.a] : 0, b = n.b >= 0 ? v[n.b] : 0;
    double& out = v[id];
    switch (n.op) {
      case Op::Constant:
        out = n.value;
        break;
      case Op::Symbol: {
        auto it = symbols.find(g.symbol_name(n.symbol));
        out = it == symbols.end() ? 0.0 : it->second;
        break;
      }
      case Op::Add:
        out = a + b;
        break;
      case Op::Sub:
        out = a - b;
        break;
      case Op::Mul:
        out = a * b;
        break;
      case Op::Div:
        out = a / b;
        break;
      case Op::Neg:
        out = -a;
        break;
      case Op::Pow:
        out = std::pow(a, n.value);
        break;
      case Op::Sin:
        out = std::sin(a);
        break;
      case Op::Cos:
        out = std::cos(a);
        break;
      case Op::Sign:
        out = double((a > 0) - (a < 0));
        break;
      case Op::Exp:
        out = std::exp(a);
        break;
      case Op::Tanh:
        out = std::tanh(a);
        break;
    }
  }
  std::vector<double> out;
  for (const NodeId r : roots_) out.push_back(v[r]);
  return out;
}

}  // namespace symoro::codegen
