// inertia.hpp: M(q; phi) from the IDM, and its basis M = constant(q) + sum_i phi[i] linear[i](q)
// from the DIM, the structure the SDP projection needs.
#include <set>

#include "headers.hpp"
#include "symoro/codegen/emitter.hpp"

namespace symoro::codegen::generate {

std::string inertia_header(ModelContext& c) {
  const int n = c.r.n;
  // M(q; phi): the derivative of the factored Newton-Euler torque (idm.txt) with respect to
  // qdd, far cheaper than summing the basis. The basis below comes from the DIM.
  const std::vector<std::vector<NodeId>> M = c.inertia_entries();
  std::vector<std::vector<NodeId>> M0(n, std::vector<NodeId>(n));
  std::map<int, double> fixed(c.fixed_index.begin(), c.fixed_index.end());
  for (int j = 0; j < n; ++j)
    for (int k = 0; k <= j; ++k) {
      NodeId constant = c.g.zero();
      for (const auto& [p, v] : fixed) constant = c.g.add(constant, c.g.mul(c.g.constant(v), c.dd[k][j][p]));
      M0[j][k] = M0[k][j] = constant;
    }
  std::string s =
      c.banner("Inertia matrix M(q; phi) = d tau / d qdd (idm.txt) and its parameter-linear basis (dim.txt).");
  s += "#include <array>\n" + c.kinematic_includes() + c.open();
  s += c.function("// The joint-space inertia matrix M(q; phi), rotor inertias included.\n", "inertia",
                  {c.q_in(), c.phi_in()}, {"M", "nq", "nq", M});
  s += "// M(q; phi) = constant(q) + sum_i phi[i] linear[i](q): the structure the SDP projection needs.\n";
  s += "template <class Scalar>\nstruct InertiaBasis {\n";
  s += "  Eigen::Matrix<Scalar, nq, nq> constant;  // from the fixed parameters (zero when they are 0)\n";
  s += "  std::array<Eigen::Matrix<Scalar, nq, nq>, np> linear;\n};\n\n";
  // One function body for the whole basis, so that shared subexpressions are computed once.
  std::map<std::string, std::string> symbols;
  for (std::size_t k = 0; k < c.r.q.size(); ++k) symbols[c.r.q[k]] = "q[" + str(static_cast<int>(k)) + "]";
  std::vector<Assignment> assignments;
  std::vector<NodeId> roots;
  auto entry = [&](const std::string& target, int j, int k, NodeId v) {
    roots.push_back(v);
    if (c.g.is_constant(v, 0.0)) return;
    assignments.push_back({target + "(" + str(j) + ", " + str(k) + ")", v});
    if (j != k) assignments.push_back({target + "(" + str(k) + ", " + str(j) + ")", v});
  };
  for (int j = 0; j < n; ++j)
    for (int k = 0; k <= j; ++k) entry("basis.constant", j, k, M0[j][k]);
  for (std::size_t i = 0; i < c.identified.size(); ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k <= j; ++k)
        entry("basis.linear[" + str(static_cast<int>(i)) + "]", j, k, c.dd[k][j][c.identified[i]]);
  c.summary->functions.push_back({"inertia_basis", count_operations(c.g, roots)});
  s += "template <class Q, class Scalar>\n";
  s += "inline void inertia_basis(const Eigen::MatrixBase<Q>& q, InertiaBasis<Scalar>& basis) {\n";
  s += c.usings(roots);
  s += "  eigen_assert(q.size() == nq);\n  static_cast<void>(q);\n";
  s += "  basis.constant.setZero();\n  for (auto& m : basis.linear) m.setZero();\n";
  s += emit_body(c.g, symbols, assignments, "  ");
  s += "}\n\n" + c.close();
  return s;
}

DimDerivatives dim_derivatives(RobotModel& r) {
  // QP and QDP vanish from d DIM / d qdd (M depends on q only).
  std::vector<NodeId> all;
  for (const auto& row : r.dim) all.insert(all.end(), row.begin(), row.end());
  std::map<std::string, NodeId> rest;
  for (const auto& s : r.qd) rest[s] = r.graph.zero();
  for (const auto& s : r.qdd) rest[s] = r.graph.zero();
  DimDerivatives dd(r.n);
  const std::set<std::string> q(r.q.begin(), r.q.end());
  for (int k = 0; k < r.n; ++k) {
    const auto flat = substitute(r.graph, differentiate(r.graph, all, r.qdd[k]), rest);
    for (const auto& s : free_symbols(r.graph, flat))
      if (!q.count(s))
        throw InputError(r.dir + "/dim.txt", 0, 0,
                         "the inertia matrix depends on " + s + ": the DIM is not linear in the accelerations");
    dd[k].assign(r.n, {});
    for (int j = 0; j < r.n; ++j)
      dd[k][j].assign(flat.begin() + j * r.base.size(), flat.begin() + (j + 1) * r.base.size());
  }
  return dd;
}

}  // namespace symoro::codegen::generate
