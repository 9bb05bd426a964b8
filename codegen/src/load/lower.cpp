// load_robot's third stage: every model file lowered into the robot's graph, and the outputs the
// generator needs picked from its equations by OpenSYMORO's names (DG<joint><parameter>, GAM<j>,
// QDP<j>, A<i><j>, T0T<frame><row><column>, J<row><column>, the base parameters). The files run
// in a fixed order, which fixes the graph's node numbering and so the generated text.
#include <initializer_list>
#include <set>

#include "equation_lowering.hpp"
#include "stages.hpp"

namespace symoro::codegen::load {

namespace {

using Env = std::map<std::string, NodeId>;
using Names = std::set<std::string>;

Names unite(std::initializer_list<const Names*> sets) {
  Names out;
  for (const auto* s : sets) out.insert(s->begin(), s->end());
  return out;
}

NodeId lookup_or_zero(const ExprGraph& g, const Env& env, const std::string& name) {
  auto it = env.find(name);
  return it == env.end() ? g.zero() : it->second;
}

// The nodes of `names`, each of which some equation of `f` must define.
std::vector<NodeId> outputs(const grammar::ModelFile& f, const Env& env, const std::vector<std::string>& names) {
  std::vector<NodeId> out;
  for (const auto& name : names) {
    auto it = env.find(name);
    if (it == env.end()) throw InputError(f.path, f.equations_at.line, 1, "no equation defines " + name);
    out.push_back(it->second);
  }
  return out;
}

// The DIM's DG<joint><base parameter> entries (0 when absent); a DG equation that names no pair
// of the tables is a mistake, not an intermediate.
void lower_identification_model(EquationLowering& lower, const grammar::ModelFile& dim, const Names& inputs,
                                RobotModel& m) {
  const auto env = lower.run(dim, inputs, "identification model (dim.txt)");
  std::set<std::string> used;
  m.dim.assign(m.n, std::vector<NodeId>(m.base.size(), m.graph.zero()));
  for (int j = 0; j < m.n; ++j)
    for (std::size_t p = 0; p < m.base.size(); ++p) {
      const std::string name = "DG" + std::to_string(j + 1) + m.base[p].name;
      m.dim[j][p] = lookup_or_zero(m.graph, env, name);
      used.insert(name);
    }
  for (const auto& eq : dim.equations)
    if (eq.name.rfind("DG", 0) == 0 && !used.count(eq.name))
      fail_at(dim.path, eq.at, "'" + eq.name + "' names no joint and base parameter of the tables");
}

// A<i><j> (0 when absent), the lower triangle mirrored.
void lower_inertia_matrix(EquationLowering& lower, const grammar::ModelFile& inm, const Names& inputs, RobotModel& m) {
  const int n = m.n;
  const auto env = lower.run(inm, inputs, "inertia matrix (inm.txt)");
  m.inm.assign(n, std::vector<NodeId>(n, m.graph.zero()));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j <= i; ++j)
      m.inm[i][j] = m.inm[j][i] = lookup_or_zero(m.graph, env, "A" + std::to_string(i + 1) + std::to_string(j + 1));
}

// The pose of the highest frame that has a T0T entry: the last arm frame.
void lower_geometric_model(EquationLowering& lower, const grammar::ModelFile& fgm, const Names& inputs, RobotModel& m) {
  const auto env = lower.run(fgm, inputs, "geometric model (fgm.txt)");
  auto entry = [](int f, int r, int c) { return "T0T" + std::to_string(f) + std::to_string(r) + std::to_string(c); };
  for (int f = m.n; f >= 1 && m.fgm_frame == 0; --f)
    for (int r = 1; r <= 3; ++r)
      for (int c = 1; c <= 4; ++c)
        if (env.count(entry(f, r, c))) m.fgm_frame = f;
  if (m.fgm_frame == 0)
    throw InputError(fgm.path, fgm.equations_at.line, 1, "no equation defines a T0T<frame><row><column> entry");
  m.fgm.assign(4, std::vector<NodeId>(4, m.graph.zero()));
  for (int r = 1; r <= 3; ++r)
    for (int c = 1; c <= 4; ++c) m.fgm[r - 1][c - 1] = lookup_or_zero(m.graph, env, entry(m.fgm_frame, r, c));
  m.fgm[3][3] = m.graph.one();
}

// J<row><column> (0 when absent), 6 x n.
void lower_jacobian(EquationLowering& lower, const grammar::ModelFile& jac, const Names& inputs, RobotModel& m) {
  const auto env = lower.run(jac, inputs, "Jacobian (jac.txt)");
  m.jac.assign(6, std::vector<NodeId>(m.n, m.graph.zero()));
  for (int r = 1; r <= 6; ++r)
    for (int c = 1; c <= m.n; ++c)
      m.jac[r - 1][c - 1] = lookup_or_zero(m.graph, env, "J" + std::to_string(r) + std::to_string(c));
}

// Each base parameter over the standard ones: its regp.txt equation, or the standard parameter
// of the same name that it is unchanged from.
void lower_base_from_standard(EquationLowering& lower, const grammar::ModelFile& regp, const Names& inputs,
                              const Names& standard, RobotModel& m) {
  const auto env = lower.run(regp, inputs, "base parameter equations (regp.txt)");
  for (const auto& p : m.base) {
    if (auto it = env.find(p.name); it != env.end()) {
      m.base_from_standard.push_back(it->second);
    } else if (standard.count(p.name)) {
      m.base_from_standard.push_back(m.graph.symbol(p.name));
    } else {
      throw InputError(regp.path, regp.equations_at.line, 1,
                       "base parameter " + p.name + " is neither defined here nor a standard parameter of the .par");
    }
  }
}

}  // namespace

void lower_robot(const RobotFiles& files, const ParameterNames& names, RobotModel& m) {
  EquationLowering lower(m.graph, m.spec.constants);
  const Names q(m.q.begin(), m.q.end()), qd(m.qd.begin(), m.qd.end()), qdd(m.qdd.begin(), m.qdd.end()),
      tau(m.tau.begin(), m.tau.end());
  const Names& params = names.base;
  lower_identification_model(lower, files.dim, unite({&q, &qd, &qdd}), m);
  m.idm = outputs(files.idm, lower.run(files.idm, unite({&q, &qd, &qdd, &params}), "inverse dynamic model (idm.txt)"),
                  m.tau);
  m.ccg = outputs(files.ccg, lower.run(files.ccg, unite({&q, &qd, &params}), "Coriolis and gravity model (ccg.txt)"),
                  m.tau);
  m.ddm = outputs(files.ddm, lower.run(files.ddm, unite({&q, &qd, &tau, &params}), "direct dynamic model (ddm.txt)"),
                  m.qdd);
  lower_inertia_matrix(lower, files.inm, unite({&q, &params}), m);
  lower_geometric_model(lower, files.fgm, q, m);
  lower_jacobian(lower, files.jac, q, m);
  lower_base_from_standard(lower, files.regp, unite({&q, &names.standard}), names.standard, m);
}

}  // namespace symoro::codegen::load
