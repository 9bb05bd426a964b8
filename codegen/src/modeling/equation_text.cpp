#include "equation_text.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>

#include "symoro/codegen/passes.hpp"

namespace symoro::codegen::modeling {

std::string number_text(double v) {
  char t[40];
  // Plain decimals where they are short (150, 0.0825), else the shortest %g (1e-05).
  if (v == 0) return "0";
  if (std::abs(v) >= 1e-4 && std::abs(v) < 1e15)
    for (int k = 0; k <= 17; ++k) {
      std::snprintf(t, sizeof t, "%.*f", k, v);
      if (std::strtod(t, nullptr) == v) return t;
    }
  for (int p = 1; p <= 17; ++p) {
    std::snprintf(t, sizeof t, "%.*g", p, v);
    if (std::strtod(t, nullptr) == v) break;
  }
  std::string s = t;
  // The grammar reads 1e-05 and 1.5e+20; a bare exponent needs no plus sign.
  if (auto e = s.find("e+"); e != std::string::npos) s.erase(e + 1, 1);
  return s;
}

namespace {

enum Prec { kSum = 1, kProduct = 2, kUnary = 3, kPower = 4, kAtom = 5 };

struct Printer {
  const ExprGraph& g;
  const std::map<NodeId, std::string>& names;

  Prec prec(NodeId id) const {
    if (names.count(id)) return kAtom;
    const Node& n = g.node(id);
    switch (n.op) {
      case Op::Constant:
        return n.value < 0 ? kUnary : kAtom;
      case Op::Add:
      case Op::Sub:
        return kSum;
      case Op::Mul:
      case Op::Div:
        return kProduct;
      case Op::Neg:
        return kUnary;
      case Op::Pow:
        return kPower;
      default:
        return kAtom;
    }
  }
  std::string wrap(NodeId id, bool need) const { return need ? "(" + text(id) + ")" : text(id); }

  std::string text(NodeId id) const {
    if (auto it = names.find(id); it != names.end()) return it->second;
    const Node& n = g.node(id);
    switch (n.op) {
      case Op::Constant:
        return number_text(n.value);
      case Op::Symbol:
        return g.symbol_name(n.symbol);
      // Operands keep the graph's grouping (a - (b - c), a*(b*c)): the text reads back to the
      // same expression, rounding included. A negation is always parenthesized as an operand.
      case Op::Add:
        return wrap(n.a, prec(n.a) == kUnary) + " + " + wrap(n.b, prec(n.b) == kSum || prec(n.b) == kUnary);
      case Op::Sub:
        return wrap(n.a, prec(n.a) == kUnary) + " - " + wrap(n.b, prec(n.b) == kSum || prec(n.b) == kUnary);
      case Op::Mul:
      case Op::Div:
        return wrap(n.a, prec(n.a) == kSum || prec(n.a) == kUnary) + (n.op == Op::Mul ? "*" : "/") +
               wrap(n.b, prec(n.b) <= kUnary);
      case Op::Neg:
        return "-" + wrap(n.a, prec(n.a) <= kSum || prec(n.a) == kUnary);
      case Op::Pow: {
        const double e = n.value;
        return wrap(n.a, prec(n.a) < kAtom) + "**" + (e < 0 ? "(" + number_text(e) + ")" : number_text(e));
      }
      case Op::Sin:
        return "sin(" + text(n.a) + ")";
      case Op::Cos:
        return "cos(" + text(n.a) + ")";
      case Op::Sign:
        return "sign(" + text(n.a) + ")";
      case Op::Exp:
        return "exp(" + text(n.a) + ")";
      case Op::Tanh:
        return "tanh(" + text(n.a) + ")";
    }
    return "";
  }
};

}  // namespace

std::string expression_text(const ExprGraph& g, NodeId root, const std::map<NodeId, std::string>& names) {
  return Printer{g, names}.text(root);
}

std::string equations_text(const ExprGraph& g, const std::vector<std::pair<std::string, NodeId>>& outputs,
                           const std::vector<std::string>& joints, const std::string& prefix) {
  std::vector<NodeId> roots;
  for (const auto& o : outputs) roots.push_back(o.second);
  const std::vector<NodeId> order = reachable(g, roots);
  std::map<NodeId, int> uses;
  for (const NodeId id : order) {
    const Node& n = g.node(id);
    if (n.a >= 0) ++uses[n.a];
    if (n.b >= 0) ++uses[n.b];
  }
  for (const NodeId r : roots) ++uses[r];
  std::map<NodeId, std::string> names;
  std::string out;
  // Sines and cosines of the joint variables, by joint.
  for (std::size_t j = 0; j < joints.size(); ++j) {
    const NodeId q = g.find_symbol(joints[j]);
    if (q < 0) continue;
    for (const NodeId id : order) {
      const Node& n = g.node(id);
      if (n.a != q || (n.op != Op::Cos && n.op != Op::Sin)) continue;
      const std::string name = (n.op == Op::Cos ? "C" : "S") + std::to_string(j + 1);
      out += name + " = " + expression_text(g, id, names) + ";\n";
      names[id] = name;
    }
  }
  // Temporaries: a name no symbol of the graph has.
  std::string p = prefix;
  auto clashes = [&](const std::string& pre) {
    for (const NodeId id : order)
      if (g.node(id).op == Op::Symbol) {
        const std::string& s = g.symbol_name(g.node(id).symbol);
        if (s.rfind(pre, 0) == 0) return true;
      }
    for (const auto& o : outputs)
      if (o.first.rfind(pre, 0) == 0 && o.first.find_first_not_of("0123456789", pre.size()) == std::string::npos)
        return true;
    return false;
  };
  while (clashes(p)) p += "x";
  std::set<NodeId> output_nodes(roots.begin(), roots.end());
  int k = 0;
  for (const NodeId id : order) {
    const Node& n = g.node(id);
    if (names.count(id) || n.op == Op::Constant || n.op == Op::Symbol) continue;
    if (n.op == Op::Neg && (g.node(n.a).op == Op::Symbol || names.count(n.a))) continue;
    if (uses[id] < 2) continue;
    const std::string name = p + std::to_string(++k);
    out += name + " = " + expression_text(g, id, names) + ";\n";
    names[id] = name;
  }
  for (const auto& [name, node] : outputs) out += name + " = " + expression_text(g, node, names) + ";\n";
  return out;
}

}  // namespace symoro::codegen::modeling
