// A direct numeric evaluator of parsed OpenSYMORO expressions and equation lists. It shares no
// code with the compiler's passes, so tests use it as an independent reference for what the
// generated C++ computes.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "symoro/grammar/ast.hpp"

namespace symoro::grammar {

using Bindings = std::map<std::string, double>;

// Evaluates `e` with the symbols in `symbols` (plus `pi`). An unknown symbol or function throws
// std::runtime_error naming it.
double evaluate(const Expr& e, const Bindings& symbols);

// Runs the equations in order, each adding (or overwriting) its name in a copy of `inputs`;
// returns all names. `sign(0)` is 0.
Bindings run_equations(const std::vector<Equation>& equations, const Bindings& inputs);

}  // namespace symoro::grammar
