// regressor.hpp: tau = W(q, qd, qdd) phi + tau0, the identification model (dim.txt) with the
// fixed parameters' torque apart.
#include "headers.hpp"
#include "symoro/codegen/emitter.hpp"

namespace symoro::codegen::generate {

std::string regressor_header(ModelContext& c) {
  const std::vector<std::vector<NodeId>> W = c.regressor_entries();
  std::vector<std::vector<NodeId>> tau0(c.r.n);
  for (int j = 0; j < c.r.n; ++j) {
    NodeId sum = c.g.zero();
    for (const auto& [p, v] : c.fixed_index) sum = c.g.add(sum, c.g.mul(c.g.constant(v), c.r.dim[j][p]));
    tau0[j] = {sum};
  }
  std::string s = c.banner("Regressor (dynamic identification model, dim.txt): tau = W(q, qd, qdd) phi + tau0.");
  s += c.kinematic_includes() + c.open();
  s += c.function("// The regressor W (nq x np) at (q, qd, qdd): tau = W phi + fixed_torque(q, qd, qdd).\n",
                  "regressor", {c.q_in(), c.qd_in(), c.qdd_in()}, {"W", "nq", "np", W});
  s += c.function("// The torque of the parameters fixed at generation time (zero when all fixed values are 0).\n",
                  "fixed_torque", {c.q_in(), c.qd_in(), c.qdd_in()}, {"tau0", "nq", "1", tau0});
  s += c.close();
  return s;
}

}  // namespace symoro::codegen::generate
