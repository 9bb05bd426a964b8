// A joint law averaged over the spread of the true velocity about the logged one: what the torque
// shows of a friction law where quantization and a servo hunting about a held posture blur the
// velocity (effects.hpp). Coulomb's and Stribeck's averages have closed forms (erf); a law added
// to the effect table gets its average by quadrature here, when it depends on qd alone.
#pragma once

#include "symoro/effect_law.hpp"

namespace symoro::diagnose::detail {

// Whether a law's value depends on q (a position harmonic) or on qd: traced through the algebra,
// not evaluated.
struct LawDependence {
  bool q = false, qd = false;
};
LawDependence law_dependence(JointLaw law, int family = 0);

// E[law(q, v)] over v ~ N(qd, spread^2): Gauss-Legendre over qd -+ 7 spreads, in two pieces when
// that range holds rest (v = 0: where sign and abs break a law's smoothness). spread <= 0: the
// law itself.
double spread_average(JointLaw law, double q, double qd, double spread, int family, double velocity, int order);

}  // namespace symoro::diagnose::detail
