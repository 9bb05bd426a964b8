// The expression graph and its passes, checked against direct numeric evaluation and finite
// differences.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "symoro/codegen/emitter.hpp"
#include "symoro/codegen/expr_graph.hpp"
#include "symoro/codegen/passes.hpp"

using namespace symoro::codegen;

namespace {

// Evaluates a node numerically: the test's own reading of the IR.
double eval(const ExprGraph& g, NodeId root, const std::map<std::string, double>& at) {
  std::map<NodeId, double> v;
  for (NodeId id : reachable(g, {root})) {
    const Node& n = g.node(id);
    auto a = [&] { return v.at(n.a); };
    auto b = [&] { return v.at(n.b); };
    switch (n.op) {
      case Op::Constant:
        v[id] = n.value;
        break;
      case Op::Symbol:
        v[id] = at.at(g.symbol_name(n.symbol));
        break;
      case Op::Add:
        v[id] = a() + b();
        break;
      case Op::Sub:
        v[id] = a() - b();
        break;
      case Op::Mul:
        v[id] = a() * b();
        break;
      case Op::Div:
        v[id] = a() / b();
        break;
      case Op::Neg:
        v[id] = -a();
        break;
      case Op::Pow:
        v[id] = std::pow(a(), n.value);
        break;
      case Op::Sin:
        v[id] = std::sin(a());
        break;
      case Op::Cos:
        v[id] = std::cos(a());
        break;
      case Op::Sign:
        v[id] = double((a() > 0) - (a() < 0));
        break;
      case Op::Exp:
        v[id] = std::exp(a());
        break;
      case Op::Tanh:
        v[id] = std::tanh(a());
        break;
    }
  }
  return v.at(root);
}

}  // namespace

TEST(ExprGraph, StructurallyEqualExpressionsAreOneNode) {
  ExprGraph g;
  const NodeId x = g.symbol("x"), y = g.symbol("y");
  EXPECT_EQ(g.mul(x, y), g.mul(y, x));
  EXPECT_EQ(g.add(g.sin(x), y), g.add(y, g.sin(x)));
  EXPECT_EQ(g.symbol("x"), x);
  EXPECT_NE(g.sub(x, y), g.sub(y, x));
  const std::size_t before = g.size();
  g.mul(g.add(x, y), g.cos(x));
  const std::size_t after = g.size();
  g.mul(g.cos(x), g.add(y, x));  // the same expression again creates nothing
  EXPECT_EQ(g.size(), after);
  EXPECT_GT(after, before);
}

TEST(ExprGraph, ConstantsAndIdentitiesFold) {
  ExprGraph g;
  const NodeId x = g.symbol("x");
  EXPECT_EQ(g.mul(x, g.zero()), g.zero());
  EXPECT_EQ(g.add(x, g.zero()), x);
  EXPECT_EQ(g.mul(g.one(), x), x);
  EXPECT_EQ(g.neg(g.neg(x)), x);
  EXPECT_EQ(g.sub(x, x), g.zero());
  EXPECT_EQ(g.div(g.zero(), x), g.zero());
  EXPECT_EQ(g.pow(x, 1.0), x);
  EXPECT_EQ(g.pow(x, 0.0), g.one());
  const NodeId c = g.mul(g.constant(2.0), g.mul(g.constant(3.0), x));
  ASSERT_EQ(g.node(c).op, Op::Mul);
  EXPECT_EQ(g.node(g.node(c).a).value, 6.0);
  EXPECT_EQ(g.node(g.add(g.constant(0.25), g.constant(0.5))).value, 0.75);
  EXPECT_EQ(g.node(g.sign(g.constant(-3.0))).value, -1.0);
  EXPECT_EQ(g.exp(g.zero()), g.one());
  EXPECT_EQ(g.node(g.exp(g.constant(2.0))).value, std::exp(2.0));
  EXPECT_EQ(g.exp(g.neg(x)), g.exp(g.neg(x)));
  EXPECT_NE(g.exp(x), g.exp(g.neg(x)));
  // a + (-2) b is written a - 2 b
  EXPECT_EQ(g.node(g.add(x, g.mul(g.constant(-2.0), g.symbol("b")))).op, Op::Sub);
}

TEST(Passes, SubstituteSpecializesAndRefolds) {
  ExprGraph g;
  const NodeId x = g.symbol("x"), fs = g.symbol("FS"), qp = g.symbol("QP");
  const NodeId tau = g.add(g.mul(fs, g.sign(qp)), g.mul(x, qp));
  const auto out = substitute(g, {tau}, {{"FS", g.zero()}});
  EXPECT_EQ(out[0], g.mul(x, qp));
  const auto rest = substitute(g, {tau}, {{"QP", g.zero()}});
  EXPECT_EQ(rest[0], g.zero());
  EXPECT_EQ(free_symbols(g, {tau}), (std::vector<std::string>{"FS", "QP", "x"}));
}

TEST(Passes, DerivativesMatchFiniteDifferences) {
  ExprGraph g;
  const NodeId x = g.symbol("x"), y = g.symbol("y");
  // A mix of every operator, shaped like the model files' expressions.
  const NodeId e = g.add(g.add(g.div(g.mul(g.sin(x), g.pow(y, 3.0)), g.add(g.constant(2.0), g.cos(g.mul(x, y)))),
                               g.sub(g.neg(g.mul(g.constant(0.5), g.pow(x, 2.0))), g.mul(g.sign(y), y))),
                         g.mul(g.sign(x), g.exp(g.neg(g.pow(g.mul(g.constant(1.5), x), 2.0)))));  // a Stribeck term
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-2, 2);
  for (int trial = 0; trial < 20; ++trial) {
    std::map<std::string, double> at{{"x", u(rng)}, {"y", u(rng)}};
    for (const char* var : {"x", "y"}) {
      const NodeId d = differentiate(g, {e}, var)[0];
      const double h = 1e-6;
      auto plus = at, minus = at;
      plus[var] += h;
      minus[var] -= h;
      const double fd = (eval(g, e, plus) - eval(g, e, minus)) / (2 * h);
      EXPECT_NEAR(eval(g, d, at), fd, 1e-6 * (1 + std::fabs(fd))) << var << " at trial " << trial;
    }
  }
  // d/dx of an expression without x folds to the constant 0.
  EXPECT_EQ(differentiate(g, {g.sin(y)}, "x")[0], g.zero());
}

TEST(Passes, OperationCountsCountSharedNodesOnce) {
  ExprGraph g;
  const NodeId s = g.sin(g.symbol("x"));
  const NodeId e = g.add(g.mul(s, s), g.mul(s, g.symbol("y")));  // s*s is a power
  const auto c = count_operations(g, {e});
  EXPECT_EQ(c.trig, 1);
  EXPECT_EQ(c.pow, 1);
  EXPECT_EQ(c.mul, 1);
  EXPECT_EQ(c.add, 1);
  EXPECT_EQ(c.exp, 0);
  const NodeId x = g.symbol("x");
  const auto ce = count_operations(g, {g.add(g.exp(x), g.mul(g.exp(x), x))});
  EXPECT_EQ(ce.exp, 1);
  EXPECT_EQ(ce.total(), 3);
}

TEST(Emitter, ExpIsWrittenAsACallResolvedForTheScalar) {
  ExprGraph g;
  const NodeId v = g.symbol("v");
  const NodeId sign = g.sign(v);  // made first: the older operand of a product is written first
  const NodeId e = g.mul(sign, g.exp(g.neg(g.pow(g.mul(g.constant(20.0), v), 2.0))));
  EXPECT_EQ(emit_body(g, {{"v", "qd[1]"}}, {{"out(0)", e}}, ""),
            "const Scalar v(qd[1]);\n"
            "const Scalar t0 = 20.0 * v;\n"
            "out(0) = sign(v) * exp(-(t0 * t0));\n");
  // d/dv reuses the exp node.
  const NodeId d = differentiate(g, {e}, "v")[0];
  EXPECT_EQ(count_operations(g, {e, d}).exp, 1);
}

TEST(Emitter, LiteralsReadBackExactly) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1e3, 1e3);
  for (int i = 0; i < 1000; ++i) {
    const double v = u(rng);
    EXPECT_EQ(std::stod(cpp_literal(v)), v);
  }
  EXPECT_EQ(cpp_literal(2.0), "2.0");
  EXPECT_EQ(cpp_literal(0.25), "0.25");
  EXPECT_EQ(cpp_literal(9.80665), "9.80665");
}

TEST(Emitter, SharedNodesAreNamedOnceAndSingleUsesInlined) {
  ExprGraph g;
  const NodeId x = g.symbol("x");
  const NodeId s = g.sin(x);
  const NodeId e1 = g.mul(s, g.constant(2.0)), e2 = g.add(s, g.symbol("y"));
  const std::string body = emit_body(g, {{"x", "q[0]"}, {"y", "q[1]"}}, {{"out(0)", e1}, {"out(1)", e2}}, "");
  EXPECT_EQ(body,
            "const Scalar x(q[0]);\n"
            "const Scalar t0 = sin(x);\n"
            "const Scalar y(q[1]);\n"
            "out(0) = 2.0 * t0;\n"
            "out(1) = t0 + y;\n");
  EXPECT_THROW(emit_body(g, {}, {{"out", e1}}, ""), std::logic_error);
}
