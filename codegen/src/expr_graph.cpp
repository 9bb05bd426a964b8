#include "symoro/codegen/expr_graph.hpp"

#include <cmath>
#include <cstring>
#include <utility>

namespace symoro::codegen {

namespace {
std::uint64_t bits_of(double v) {
  if (v == 0.0) v = 0.0;  // one zero: -0.0 and 0.0 are the same constant
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}
}  // namespace

std::size_t ExprGraph::KeyHash::operator()(const Key& k) const {
  std::uint64_t h = static_cast<std::uint64_t>(k.op);
  auto mix = [&h](std::uint64_t v) { h ^= v + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2); };
  mix(static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.a)));
  mix(static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.b)));
  mix(k.bits);
  mix(static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.symbol)));
  return static_cast<std::size_t>(h);
}

ExprGraph::ExprGraph() {
  zero_ = constant(0.0);
  one_ = constant(1.0);
}

NodeId ExprGraph::intern(Node n) {
  if (n.op == Op::Constant && n.value == 0.0) n.value = 0.0;
  const Key key{n.op, n.a, n.b, bits_of(n.value), n.symbol};
  auto it = index_.find(key);
  if (it != index_.end()) return it->second;
  const auto id = static_cast<NodeId>(nodes_.size());
  nodes_.push_back(n);
  index_.emplace(key, id);
  return id;
}

NodeId ExprGraph::constant(double v) { return intern(Node{Op::Constant, -1, -1, v, -1}); }

NodeId ExprGraph::symbol(const std::string& name) {
  auto it = symbol_index_.find(name);
  int s;
  if (it == symbol_index_.end()) {
    s = static_cast<int>(symbols_.size());
    symbols_.push_back(name);
    symbol_index_.emplace(name, s);
  } else {
    s = it->second;
  }
  return intern(Node{Op::Symbol, -1, -1, 0.0, s});
}

NodeId ExprGraph::find_symbol(const std::string& name) const {
  auto it = symbol_index_.find(name);
  if (it == symbol_index_.end()) return -1;
  const Key key{Op::Symbol, -1, -1, bits_of(0.0), it->second};
  auto n = index_.find(key);
  return n == index_.end() ? -1 : n->second;
}

// c * x with a negative constant c: a + c x is better written a - |c| x.
bool ExprGraph::negative_scaled(NodeId id) const {
  const Node& n = node(id);
  return n.op == Op::Mul && is_constant(n.a) && node(n.a).value < 0;
}

// Commutative operands are ordered: a constant first, otherwise the older node first, so that
// a*b and b*a are one node.
static void order(const ExprGraph& g, NodeId& a, NodeId& b) {
  const bool ca = g.is_constant(a), cb = g.is_constant(b);
  if ((cb && !ca) || (ca == cb && b < a)) std::swap(a, b);
}

NodeId ExprGraph::add(NodeId a, NodeId b) {
  if (is_constant(a) && is_constant(b)) return constant(node(a).value + node(b).value);
  if (is_constant(a, 0.0)) return b;
  if (is_constant(b, 0.0)) return a;
  if (node(b).op == Op::Neg) return sub(a, node(b).a);
  if (node(a).op == Op::Neg) return sub(b, node(a).a);
  if (negative_scaled(b)) return sub(a, mul(constant(-node(node(b).a).value), node(b).b));
  if (negative_scaled(a)) return sub(b, mul(constant(-node(node(a).a).value), node(a).b));
  order(*this, a, b);
  return intern(Node{Op::Add, a, b, 0.0, -1});
}

NodeId ExprGraph::sub(NodeId a, NodeId b) {
  if (is_constant(a) && is_constant(b)) return constant(node(a).value - node(b).value);
  if (is_constant(b, 0.0)) return a;
  if (is_constant(a, 0.0)) return neg(b);
  if (a == b) return zero_;
  if (node(b).op == Op::Neg) return add(a, node(b).a);
  if (node(a).op == Op::Neg) return neg(add(node(a).a, b));
  if (negative_scaled(b)) return add(a, mul(constant(-node(node(b).a).value), node(b).b));
  return intern(Node{Op::Sub, a, b, 0.0, -1});
}

NodeId ExprGraph::mul(NodeId a, NodeId b) {
  if (is_constant(a) && is_constant(b)) return constant(node(a).value * node(b).value);
  order(*this, a, b);  // a constant, if any, is now `a`
  if (is_constant(a)) {
    const double c = node(a).value;
    if (c == 0.0) return zero_;
    if (c == 1.0) return b;
    if (c == -1.0) return neg(b);
    const Node& nb = node(b);
    // c1 * (c2 * x) = (c1 c2) * x
    if (nb.op == Op::Mul && is_constant(nb.a)) return mul(constant(c * node(nb.a).value), nb.b);
    if (nb.op == Op::Neg) return mul(constant(-c), nb.a);
  }
  if (node(a).op == Op::Neg && node(b).op == Op::Neg) return mul(node(a).a, node(b).a);
  if (node(a).op == Op::Neg) return neg(mul(node(a).a, b));
  if (node(b).op == Op::Neg) return neg(mul(a, node(b).a));
  if (a == b) return pow(a, 2.0);
  return intern(Node{Op::Mul, a, b, 0.0, -1});
}

NodeId ExprGraph::div(NodeId a, NodeId b) {
  if (is_constant(a) && is_constant(b) && node(b).value != 0.0) return constant(node(a).value / node(b).value);
  if (is_constant(a, 0.0)) return zero_;
  if (is_constant(b, 1.0)) return a;
  if (is_constant(b, -1.0)) return neg(a);
  // x / c = (1/c) * x: a multiplication is cheaper and exposes the constant to folding.
  if (is_constant(b) && node(b).value != 0.0) return mul(constant(1.0 / node(b).value), a);
  if (node(a).op == Op::Neg) return neg(div(node(a).a, b));
  if (node(b).op == Op::Neg) return neg(div(a, node(b).a));
  return intern(Node{Op::Div, a, b, 0.0, -1});
}

NodeId ExprGraph::neg(NodeId a) {
  if (is_constant(a)) return constant(-node(a).value);
  if (node(a).op == Op::Neg) return node(a).a;
  return intern(Node{Op::Neg, a, -1, 0.0, -1});
}

NodeId ExprGraph::pow(NodeId a, double exponent) {
  if (exponent == 0.0) return one_;
  if (exponent == 1.0) return a;
  if (is_constant(a)) return constant(std::pow(node(a).value, exponent));
  const double e = exponent;
  // (-x)^k = x^k for even k, -(x^k) for odd k.
  if (node(a).op == Op::Neg && std::floor(e) == e) {
    const NodeId p = pow(node(a).a, e);
    return std::fmod(std::fabs(e), 2.0) == 0.0 ? p : neg(p);
  }
  return intern(Node{Op::Pow, a, -1, e, -1});
}

NodeId ExprGraph::sin(NodeId a) {
  if (is_constant(a)) return constant(std::sin(node(a).value));
  if (node(a).op == Op::Neg) return neg(sin(node(a).a));
  return intern(Node{Op::Sin, a, -1, 0.0, -1});
}

NodeId ExprGraph::cos(NodeId a) {
  if (is_constant(a)) return constant(std::cos(node(a).value));
  if (node(a).op == Op::Neg) return cos(node(a).a);
  return intern(Node{Op::Cos, a, -1, 0.0, -1});
}

NodeId ExprGraph::sign(NodeId a) {
  if (is_constant(a)) {
    const double v = node(a).value;
    return constant(double((v > 0) - (v < 0)));
  }
  if (node(a).op == Op::Neg) return neg(sign(node(a).a));
  return intern(Node{Op::Sign, a, -1, 0.0, -1});
}

NodeId ExprGraph::tanh(NodeId a) {
  if (is_constant(a)) return constant(std::tanh(node(a).value));
  if (node(a).op == Op::Neg) return neg(tanh(node(a).a));  // odd, like sign
  return intern(Node{Op::Tanh, a, -1, 0.0, -1});
}

NodeId ExprGraph::exp(NodeId a) {
  if (is_constant(a)) return constant(std::exp(node(a).value));  // exp(0) = 1 exactly
  return intern(Node{Op::Exp, a, -1, 0.0, -1});
}

}  // namespace symoro::codegen
