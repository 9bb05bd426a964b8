#include "symoro/codegen/emitter.hpp"

#include <charconv>
#include <cmath>
#include <regex>
#include <stdexcept>
#include <unordered_map>

#include "symoro/codegen/passes.hpp"

namespace symoro::codegen {

std::string cpp_literal(double v) {
  if (!std::isfinite(v)) throw std::logic_error("non-finite constant in generated code");
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);  // shortest round-trip form
  std::string s(buf, res.ptr);
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

namespace {

using Text = BodyEmitter::Text;
enum Prec {
  kSum = BodyEmitter::kSum,
  kProduct = BodyEmitter::kProduct,
  kUnary = BodyEmitter::kUnary,
  kAtom = BodyEmitter::kAtom
};

std::string wrap(const Text& t, int min_prec) { return t.prec >= min_prec ? t.s : "(" + t.s + ")"; }

constexpr std::size_t kMaxInlineLength = 90;

}  // namespace

BodyEmitter::BodyEmitter(const ExprGraph& g, std::map<std::string, std::string> inputs,
                         const std::vector<NodeId>& all_roots, std::string indent)
    : g_(g), inputs_(std::move(inputs)), indent_(std::move(indent)) {
  for (NodeId id : reachable(g_, all_roots)) {
    const Node& n = g_.node(id);
    if (n.a >= 0) ++uses_[n.a];
    if (n.b >= 0) ++uses_[n.b];
    if (n.op == Op::Pow) pow_operand_.insert(n.a);  // a power's operand is always named: x*x repeats it
  }
  for (NodeId r : all_roots) ++uses_[r];
}

std::string BodyEmitter::emit(const std::vector<Assignment>& outputs) {
  static const std::regex plain_name("^[A-Za-z][A-Za-z0-9_]*$");
  static const std::regex reserved(
      "^(t[0-9]+|Scalar|q|qd|qdd|tau|phi|s|out|[A-Z]|M|W|T|J|h|basis|sin|cos|sign|pow|exp|int|do|if|for|new|and|or|not|"
      "xor|auto|case|char|long|this|true|false|void|ldlt|stage_[a-z_]+)$");
  std::vector<NodeId> roots;
  for (const auto& o : outputs) roots.push_back(o.value);
  std::string body;
  for (NodeId id : reachable(g_, roots)) {
    if (text_.count(id)) continue;  // computed by an earlier stage
    const Node& n = g_.node(id);
    if (n.op == Op::Symbol) {
      const std::string& name = g_.symbol_name(n.symbol);
      auto it = inputs_.find(name);
      if (it == inputs_.end()) throw std::logic_error("symbol '" + name + "' is not an input of this function");
      std::string local = std::regex_match(name, plain_name) && !std::regex_match(name, reserved) ? name : "s_" + name;
      body += indent_ + "const Scalar " + local + "(" + it->second + ");\n";
      text_[id] = {local, kAtom};
      continue;
    }
    if (n.op == Op::Constant) {
      text_[id] = {cpp_literal(n.value), n.value < 0 ? kUnary : kAtom};
      continue;
    }
    auto arg = [&](NodeId c) -> const Text& { return text_.at(c); };
    Text t;
    switch (n.op) {
      case Op::Add:
        t = {wrap(arg(n.a), kSum) + " + " + wrap(arg(n.b), kProduct), kSum};
        break;
      case Op::Sub:
        t = {wrap(arg(n.a), kSum) + " - " + wrap(arg(n.b), kProduct), kSum};
        break;
      case Op::Mul:
        t = {wrap(arg(n.a), kProduct) + " * " + wrap(arg(n.b), kUnary), kProduct};
        break;
      case Op::Div:
        t = {wrap(arg(n.a), kProduct) + " / " + wrap(arg(n.b), kUnary), kProduct};
        break;
      case Op::Neg:
        t = {"-" + wrap(arg(n.a), kUnary), kUnary};
        break;
      case Op::Sin:
        t = {"sin(" + arg(n.a).s + ")", kAtom};
        break;
      case Op::Cos:
        t = {"cos(" + arg(n.a).s + ")", kAtom};
        break;
      case Op::Sign:
        t = {"sign(" + arg(n.a).s + ")", kAtom};
        break;
      case Op::Exp:
        t = {"exp(" + arg(n.a).s + ")", kAtom};
        break;
      case Op::Tanh:
        t = {"tanh(" + arg(n.a).s + ")", kAtom};
        break;
      case Op::Pow: {
        const double e = n.value;
        const std::string x = wrap(arg(n.a), kAtom);
        if (e == std::floor(e) && std::fabs(e) <= 4) {
          std::string p = x;
          for (int i = 1; i < static_cast<int>(std::fabs(e)); ++i) p += " * " + x;
          t = e > 0 ? Text{p, kProduct} : Text{"1.0 / (" + p + ")", kProduct};
        } else {
          t = {"pow(" + arg(n.a).s + ", " + cpp_literal(e) + ")", kAtom};
        }
        break;
      }
      case Op::Constant:
      case Op::Symbol:
        break;
    }
    // A node used once is written inline into its user.
    if (uses_[id] == 1 && t.s.size() <= kMaxInlineLength && !pow_operand_.count(id)) {
      text_[id] = t;
    } else {
      const std::string name = "t" + std::to_string(temps_++);
      body += indent_ + "const Scalar " + name + " = " + t.s + ";\n";
      text_[id] = {name, kAtom};
    }
  }
  for (const auto& o : outputs) {
    const Node& n = g_.node(o.value);
    const std::string v = n.op == Op::Constant ? "Scalar(" + cpp_literal(n.value) + ")" : text_.at(o.value).s;
    body += indent_ + o.target + " = " + v + ";\n";
  }
  return body;
}

std::string math_usings(const ExprGraph& g, const std::vector<NodeId>& roots) {
  bool exp = false, tanh = false;
  for (NodeId id : reachable(g, roots)) {
    exp = exp || g.node(id).op == Op::Exp;
    tanh = tanh || g.node(id).op == Op::Tanh;
  }
  return std::string("  using std::cos;\n") + (exp ? "  using std::exp;\n" : "") +
         "  using std::pow;\n  using std::sin;\n" + (tanh ? "  using std::tanh;\n" : "") + "  using ::symoro::sign;\n";
}

std::string emit_body(const ExprGraph& g, const std::map<std::string, std::string>& inputs,
                      const std::vector<Assignment>& outputs, const std::string& indent) {
  std::vector<NodeId> roots;
  for (const auto& o : outputs) roots.push_back(o.value);
  BodyEmitter e(g, inputs, roots, indent);
  return e.emit(outputs);
}

}  // namespace symoro::codegen
