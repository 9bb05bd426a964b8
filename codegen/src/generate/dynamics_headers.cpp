// The dynamic models, one function each over the robot's expressions with the model's fixed
// values and effect torques in: inverse dynamics (idm.txt), nonlinear effects (ccg.txt) and
// forward dynamics (ddm.txt).
#include "headers.hpp"

namespace symoro::codegen::generate {

std::string inverse_dynamics_header(ModelContext& c) {
  std::string s = c.banner("Inverse dynamics (Newton-Euler, idm.txt).");
  s += c.kinematic_includes() + c.open();
  s += c.function("// Joint torques tau(q, qd, qdd; phi), friction and rotor inertia included.\n", "inverse_dynamics",
                  {c.q_in(), c.qd_in(), c.qdd_in(), c.phi_in()},
                  {"tau", "nq", "1", column(c.plus_effects(c.specialize(c.r.idm)))});
  s += c.close();
  return s;
}

std::string nonlinear_effects_header(ModelContext& c) {
  std::string s = c.banner("Coriolis, centrifugal, gravity and friction torques (ccg.txt).");
  s += c.kinematic_includes() + c.open();
  s += c.function("// h(q, qd; phi) = tau(q, qd, 0; phi): Coriolis, centrifugal, gravity and friction.\n",
                  "nonlinear_effects", {c.q_in(), c.qd_in(), c.phi_in()},
                  {"h", "nq", "1", column(c.plus_effects(c.specialize(c.r.ccg)))});
  s += c.close();
  return s;
}

std::string forward_dynamics_header(ModelContext& c) {
  // The effects' torques act like friction: ddm.txt runs on GAM - (their sum) per joint.
  std::map<std::string, NodeId> replacements = c.replacements;
  for (int j = 0; j < c.r.n; ++j) {
    const NodeId t = c.effect_torque(j);
    if (t != c.g.zero()) replacements[c.r.tau[j]] = c.g.sub(c.g.symbol(c.r.tau[j]), t);
  }
  const auto qdd = substitute(c.g, c.r.ddm, replacements);
  std::string s = c.banner("Forward dynamics (direct dynamic model, ddm.txt).");
  s += c.kinematic_includes() + c.open();
  s += c.function("// Joint accelerations qdd(q, qd, tau; phi) = M^-1 (tau - h).\n", "forward_dynamics",
                  {c.q_in(), c.qd_in(), c.tau_in(), c.phi_in()}, {"qdd", "nq", "1", column(qdd)});
  s += c.close();
  return s;
}

}  // namespace symoro::codegen::generate
