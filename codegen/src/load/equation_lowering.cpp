#include "equation_lowering.hpp"

#include <cmath>
#include <vector>

#include "stages.hpp"

namespace symoro::codegen::load {

using grammar::Expr;

EquationLowering::EquationLowering(ExprGraph& g, const std::map<std::string, double>& constants) : g_(g) {
  for (const auto& [k, v] : constants) constants_[k] = g.constant(v);
  constants_.emplace("pi", g.constant(M_PI));
}

std::map<std::string, NodeId> EquationLowering::run(const grammar::ModelFile& file, const std::set<std::string>& inputs,
                                                    const std::string& role) {
  std::map<std::string, NodeId> env;
  for (const auto& eq : file.equations) env[eq.name] = lower(eq.value, env, inputs, file.path, role);
  return env;
}

NodeId EquationLowering::leaf(const Expr& e, const std::map<std::string, NodeId>& env,
                              const std::set<std::string>& inputs, const std::string& path, const std::string& role) {
  if (auto it = env.find(e.name); it != env.end()) return it->second;
  if (inputs.count(e.name)) return g_.symbol(e.name);
  if (auto it = constants_.find(e.name); it != constants_.end()) return it->second;
  fail_at(path, e.at,
          "unknown symbol '" + e.name + "': not defined by an earlier equation, not an input of the " + role +
              ", and not a constant in robot.yaml");
}

// Post-order walk with an explicit stack: long operator chains make deep trees.
NodeId EquationLowering::lower(const Expr& root, const std::map<std::string, NodeId>& env,
                               const std::set<std::string>& inputs, const std::string& path, const std::string& role) {
  struct Item {
    const Expr* e;
    std::size_t next;
  };
  std::vector<Item> stack{{&root, 0}};
  std::vector<NodeId> values;
  while (!stack.empty()) {
    const Expr* e = stack.back().e;
    if (stack.back().next < e->args.size()) {
      const Expr* child = &e->args[stack.back().next++];
      stack.push_back({child, 0});
      continue;
    }
    stack.pop_back();
    const std::size_t k = e->args.size();
    const NodeId* a = values.data() + (values.size() - k);
    NodeId out = -1;
    switch (e->kind) {
      case Expr::Kind::Number:
        out = g_.constant(e->number);
        break;
      case Expr::Kind::Symbol:
        out = leaf(*e, env, inputs, path, role);
        break;
      case Expr::Kind::Negate:
        out = g_.neg(a[0]);
        break;
      case Expr::Kind::Add:
        out = g_.add(a[0], a[1]);
        break;
      case Expr::Kind::Subtract:
        out = g_.sub(a[0], a[1]);
        break;
      case Expr::Kind::Multiply:
        out = g_.mul(a[0], a[1]);
        break;
      case Expr::Kind::Divide:
        out = g_.div(a[0], a[1]);
        break;
      case Expr::Kind::Power:
        if (!g_.is_constant(a[1])) fail_at(path, e->args[1].at, "the exponent must be a constant");
        out = g_.pow(a[0], g_.node(a[1]).value);
        break;
      case Expr::Kind::Call:
        if (k != 1) fail_at(path, e->at, "'" + e->name + "' takes one argument");
        if (e->name == "sin")
          out = g_.sin(a[0]);
        else if (e->name == "cos")
          out = g_.cos(a[0]);
        else if (e->name == "sign")
          out = g_.sign(a[0]);
        else
          fail_at(path, e->at, "unknown function '" + e->name + "' (supported: sin, cos, sign)");
        break;
    }
    values.resize(values.size() - k);
    values.push_back(out);
  }
  return values.back();
}

}  // namespace symoro::codegen::load
