// A joint law: the torque term an effect parameter multiplies on its joint's row, a function of the
// joint's position q and velocity qd, written once over an algebra and read three ways: as numbers
// by the diagnosis and the tests (LawValues below), as expression-graph nodes by the compiler
// (codegen/src/effects.cpp), and as text by `symoroc info`. The effect table
// (symoro/effect_table.hpp) holds each row's law. Header-only and free of other headers of the
// project: symoroc reads it without linking the runtime.
//
// A law builds its value one statement at a time, never two node-making calls as arguments of
// one call: the order in which C++ evaluates a call's arguments is unspecified, and the compiler's
// node ids (hence the generated code) must not depend on it.
#pragma once

#include <array>
#include <cmath>
#include <stdexcept>
#include <string_view>

namespace symoro {

// The operations a law may use. Values are handles the algebra owns (a number's slot, a graph
// node, a piece of text).
class LawAlgebra {
 public:
  using Value = int;
  virtual Value constant(double c) = 0;
  virtual Value add(Value a, Value b) = 0;
  virtual Value sub(Value a, Value b) = 0;
  virtual Value mul(Value a, Value b) = 0;
  virtual Value div(Value a, Value b) = 0;
  virtual Value neg(Value a) = 0;
  virtual Value square(Value a) = 0;
  virtual Value abs(Value a) = 0;
  virtual Value sign(Value a) = 0;  // 0 at 0
  virtual Value exp(Value a) = 0;
  virtual Value tanh(Value a) = 0;
  virtual Value sin(Value a) = 0;
  virtual Value cos(Value a) = 0;

 protected:
  ~LawAlgebra() = default;
};

// What a law is evaluated at: its joint's q and qd, which of its row's families the parameter
// is (0 for the first: HS, 1: HC), the velocity scale of a row that has one, the harmonic order.
struct LawInputs {
  LawAlgebra::Value q, qd;
  int family = 0;
  double velocity = 0;
  int order = 0;
};

using JointLaw = LawAlgebra::Value (*)(LawAlgebra&, const LawInputs&);

// A law's value at numbers: the slots of one evaluation, on the stack.
class LawValues final : public LawAlgebra {
 public:
  // The law at (q, qd) for one parameter of its row.
  static double evaluate(JointLaw law, double q, double qd, int family = 0, double velocity = 0, int order = 0) {
    LawValues a;
    const Value vq = a.put(q), vqd = a.put(qd);
    return a.at(law(a, {vq, vqd, family, velocity, order}));
  }

  Value constant(double c) override { return put(c); }
  Value add(Value a, Value b) override { return put(at(a) + at(b)); }
  Value sub(Value a, Value b) override { return put(at(a) - at(b)); }
  Value mul(Value a, Value b) override { return put(at(a) * at(b)); }
  Value div(Value a, Value b) override { return put(at(a) / at(b)); }
  Value neg(Value a) override { return put(-at(a)); }
  Value square(Value a) override { return put(at(a) * at(a)); }
  Value abs(Value a) override { return put(std::abs(at(a))); }
  Value sign(Value a) override { return put(at(a) > 0 ? 1.0 : at(a) < 0 ? -1.0 : 0.0); }
  Value exp(Value a) override { return put(std::exp(at(a))); }
  Value tanh(Value a) override { return put(std::tanh(at(a))); }
  Value sin(Value a) override { return put(std::sin(at(a))); }
  Value cos(Value a) override { return put(std::cos(at(a))); }

 private:
  Value put(double v) {
    if (used_ == slots_.size()) throw std::length_error("a joint law of more than 64 steps");
    slots_[used_] = v;
    return static_cast<Value>(used_++);
  }
  double at(Value v) const { return slots_[static_cast<std::size_t>(v)]; }

  std::array<double, 64> slots_;  // written before read: put() fills what at() reads
  std::size_t used_ = 0;
};

}  // namespace symoro
