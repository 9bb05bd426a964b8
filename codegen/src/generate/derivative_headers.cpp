// The derivative headers: the model's expressions (fixed values and effects in) handed to
// derivative_functions.cpp, which writes the functions, inside the model's banner and namespace.
#include "../derivative_functions.hpp"
#include "headers.hpp"

namespace symoro::codegen::generate {

namespace {

detail::DerivativeModel derivative_model(ModelContext& c) {
  detail::DerivativeModel m;
  m.graph = &c.g;
  m.n = c.r.n;
  m.np = c.np();
  m.q = c.r.q;
  m.qd = c.r.qd;
  m.qdd = c.r.qdd;
  m.tau = c.r.tau;
  m.phi = c.identified_names();
  m.id = c.plus_effects(c.specialize(c.r.idm));
  m.M = c.inertia_entries();
  m.h = c.plus_effects(c.specialize(c.r.ccg));
  m.W = c.regressor_entries();
  return m;
}

}  // namespace

std::string inverse_dynamics_derivatives_header(ModelContext& c) {
  std::string s =
      c.banner("Inverse dynamics and its derivatives d tau / d(q, qd), differentiated on the expression graph.");
  s += c.kinematic_includes() + c.open();
  s += detail::inverse_dynamics_derivatives_code(derivative_model(c), c.summary->functions);
  s += c.close();
  return s;
}

std::string forward_dynamics_derivatives_header(ModelContext& c) {
  std::string s = c.banner("Forward dynamics with d qdd / d(q, qd, tau, phi) in one pass (one LDL^T of M).");
  s += c.kinematic_includes() + "#include \"symoro/spd_inverse.hpp\"\n\n" + c.open();
  s += detail::forward_dynamics_derivatives_code(derivative_model(c), c.summary->functions);
  s += c.close();
  return s;
}

std::string inertia_derivatives_header(ModelContext& c) {
  std::string s = c.banner("The inertia matrix M(q; phi) with d M / d q, differentiated on the expression graph.");
  s += "#include <array>\n" + c.kinematic_includes() + c.open();
  s += detail::inertia_derivatives_code(derivative_model(c), c.summary->functions);
  s += c.close();
  return s;
}

}  // namespace symoro::codegen::generate
