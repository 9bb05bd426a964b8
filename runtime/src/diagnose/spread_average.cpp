// A joint law averaged over a velocity spread (spread_average.hpp).
#include "spread_average.hpp"

#include <cmath>

#include <boost/math/quadrature/gauss.hpp>

namespace symoro::diagnose::detail {

namespace {

// Each value is the set of inputs it depends on (bit 1: q, bit 2: qd).
class DependenceLaw final : public LawAlgebra {
 public:
  Value constant(double) override { return 0; }
  Value add(Value a, Value b) override { return a | b; }
  Value sub(Value a, Value b) override { return a | b; }
  Value mul(Value a, Value b) override { return a | b; }
  Value div(Value a, Value b) override { return a | b; }
  Value neg(Value a) override { return a; }
  Value square(Value a) override { return a; }
  Value abs(Value a) override { return a; }
  Value sign(Value a) override { return a; }
  Value exp(Value a) override { return a; }
  Value tanh(Value a) override { return a; }
  Value sin(Value a) override { return a; }
  Value cos(Value a) override { return a; }
};

constexpr double kReach = 7.0;  // spreads each side: the normal's mass beyond is 3e-12

}  // namespace

LawDependence law_dependence(JointLaw law, int family) {
  DependenceLaw a;
  const LawAlgebra::Value v = law(a, {1, 2, family, 1.0, 1});
  return {(v & 1) != 0, (v & 2) != 0};
}

double spread_average(JointLaw law, double q, double qd, double spread, int family, double velocity, int order) {
  if (!(spread > 0)) return LawValues::evaluate(law, q, qd, family, velocity, order);
  // The law's sum over the nodes weighted by the normal density, over the density's own sum on
  // the same nodes: the rule's error on the density (5e-7 over 7 spreads) cancels.
  double weighted = 0, mass = 0;
  const auto piece = [&](double a, double b) {
    using Rule = boost::math::quadrature::gauss<double, 20>;
    const double mid = (a + b) / 2, half = (b - a) / 2;
    for (std::size_t i = 0; i < Rule::abscissa().size(); ++i)
      for (double side : {-1.0, 1.0}) {
        if (Rule::abscissa()[i] == 0 && side < 0) continue;  // the middle node, once
        const double v = mid + side * half * Rule::abscissa()[i];
        const double z = (v - qd) / spread;
        const double w = Rule::weights()[i] * half * std::exp(-0.5 * z * z);
        weighted += w * LawValues::evaluate(law, q, v, family, velocity, order);
        mass += w;
      }
  };
  const double lo = qd - kReach * spread, hi = qd + kReach * spread;
  if (lo < 0 && hi > 0) {
    piece(lo, 0.0);
    piece(0.0, hi);
  } else {
    piece(lo, hi);
  }
  return weighted / mass;
}

}  // namespace symoro::diagnose::detail
