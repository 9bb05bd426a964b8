#include "symoro/grammar/evaluate.hpp"

#include <cmath>
#include <stdexcept>

namespace symoro::grammar {

double evaluate(const Expr& e, const Bindings& symbols) {
  switch (e.kind) {
    case Expr::Kind::Number:
      return e.number;
    case Expr::Kind::Symbol: {
      auto it = symbols.find(e.name);
      if (it != symbols.end()) return it->second;
      if (e.name == "pi") return M_PI;
      throw std::runtime_error("unknown symbol '" + e.name + "' at line " + std::to_string(e.at.line));
    }
    case Expr::Kind::Negate:
      return -evaluate(e.args.at(0), symbols);
    case Expr::Kind::Add:
      return evaluate(e.args.at(0), symbols) + evaluate(e.args.at(1), symbols);
    case Expr::Kind::Subtract:
      return evaluate(e.args.at(0), symbols) - evaluate(e.args.at(1), symbols);
    case Expr::Kind::Multiply:
      return evaluate(e.args.at(0), symbols) * evaluate(e.args.at(1), symbols);
    case Expr::Kind::Divide:
      return evaluate(e.args.at(0), symbols) / evaluate(e.args.at(1), symbols);
    case Expr::Kind::Power:
      return std::pow(evaluate(e.args.at(0), symbols), evaluate(e.args.at(1), symbols));
    case Expr::Kind::Call: {
      if (e.args.size() != 1) throw std::runtime_error("function '" + e.name + "' takes one argument");
      const double x = evaluate(e.args[0], symbols);
      if (e.name == "sin") return std::sin(x);
      if (e.name == "cos") return std::cos(x);
      if (e.name == "sign") return double((x > 0) - (x < 0));
      if (e.name == "sqrt") return std::sqrt(x);
      if (e.name == "abs") return std::fabs(x);
      throw std::runtime_error("unknown function '" + e.name + "'");
    }
  }
  throw std::logic_error("bad expression kind");
}

Bindings run_equations(const std::vector<Equation>& equations, const Bindings& inputs) {
  Bindings values = inputs;
  for (const auto& eq : equations) values[eq.name] = evaluate(eq.value, values);
  return values;
}

}  // namespace symoro::grammar
