#include "symoro/codegen/modeling.hpp"

#include <algorithm>
#include <functional>

#include "base_parameters.hpp"
#include "description.hpp"
#include "equation_text.hpp"
#include "newton_euler.hpp"
#include "urdf_chain.hpp"
#include "symoro/codegen/passes.hpp"
#include "symoro/codegen/robot_spec.hpp"
#include "symoro/grammar/parser.hpp"

namespace symoro::codegen {

namespace {

using namespace modeling;

std::string pad(const std::string& s) {
  return s + std::string(std::max<std::size_t>(1, 8 > s.size() ? 8 - s.size() : 1), ' ');
}

std::string table(const std::string& title, const std::vector<std::string>& columns,
                  const std::vector<std::vector<std::string>>& rows) {
  std::string out = title + "\n";
  for (const auto& c : columns) out += pad(c);
  out += "\n";
  for (const auto& r : rows) {
    for (const auto& c : r) out += pad(c);
    out += "\n";
  }
  return out + "\n";
}

std::string node_text(const ExprGraph& g, NodeId id) { return expression_text(g, id, {}); }

struct Tables {
  const ExprGraph& g;
  const Description& d;

  std::string geometric() const {
    std::vector<std::vector<std::string>> rows;
    for (int j = 0; j < d.n; ++j) {
      const auto& jd = d.joints[j];
      rows.push_back({std::to_string(j + 1), std::to_string(jd.ant), std::to_string(jd.sigma), std::to_string(jd.mu),
                      to_text(jd.gamma), to_text(jd.b), to_text(jd.alpha), to_text(jd.d), to_text(jd.theta),
                      to_text(jd.r)});
    }
    return table("Geometric parameters", {"j", "ant", "sigma", "mu", "gamma", "b", "alpha", "d", "theta", "r"}, rows);
  }
  std::string inertia(const std::vector<LinkParameters>& links) const {
    std::vector<std::vector<std::string>> rows;
    for (int j = 0; j < d.n; ++j) {
      std::vector<std::string> r{std::to_string(j + 1)};
      for (const NodeId p : links[j].inertial) r.push_back(node_text(g, p));
      r.push_back(node_text(g, links[j].ia));
      rows.push_back(r);
    }
    return table("Dynamic inertia parameters", {"j", "XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M", "IA"},
                 rows);
  }
  std::string joint(const std::vector<LinkParameters>& links) const {
    std::vector<std::vector<std::string>> rows;
    for (int j = 0; j < d.n; ++j) {
      const auto& jd = d.joints[j];
      rows.push_back({std::to_string(j + 1), "0", "0", "0", "0", "0", "0", node_text(g, links[j].fs),
                      node_text(g, links[j].fv), jd.qd, jd.qdd, jd.tau, "0", "0"});
    }
    return table("External forces and joint parameters",
                 {"j", "FX", "FY", "FZ", "CX", "CY", "CZ", "FS", "FV", "QP", "QDP", "GAM", "eta", "k"}, rows);
  }
  std::string base() const {
    std::vector<std::vector<std::string>> rows;
    const char* axes[3] = {"X", "Y", "Z"};
    for (int a = 0; a < 3; ++a) rows.push_back({axes[a], "0", "0", "0", "0", to_text(d.gravity_expr[a])});
    return table("Base velocity parameters", {"axis", "W0", "WP0", "V0", "VP0", "G"}, rows);
  }
  std::string dynamic(const std::vector<LinkParameters>& links) const {
    return geometric() + inertia(links) + joint(links) + base();
  }
};

std::string model_file(const std::vector<std::string>& title, const std::string& tables, const std::string& equations) {
  std::string out;
  for (const auto& t : title) out += t + "\n";
  return out + "\n" + tables + "Equations:\n" + equations + "*=*\n";
}

std::string list(const std::vector<std::string>& v) {
  std::string s = "{";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? "," : "") + v[i];
  return s + "}";
}

// The robot re-described with its base parameters (OpenSYMORO's <robot>_base.par).
std::string base_par(const ExprGraph& g, const Description& d, const std::vector<LinkParameters>& links) {
  auto column = [&](auto get) {
    std::vector<std::string> v;
    for (int j = 0; j < d.n; ++j) v.push_back(get(j));
    return list(v);
  };
  auto zeros = [&](int k) { return list(std::vector<std::string>(k, "0")); };
  std::string s = "(* Robotname = '" + d.name + "_base' *)\n";
  s += "NL = " + std::to_string(d.n) + "\nNJ = " + std::to_string(d.n) + "\nNF = " + std::to_string(d.n) +
       "\nType = 0\nis_floating = False\nis_mobile = False\n\n(* Geometric parameters *)\n";
  s += "ant = " + column([&](int j) { return std::to_string(d.joints[j].ant); }) + "\n";
  s += "sigma = " + column([&](int j) { return std::to_string(d.joints[j].sigma); }) + "\n";
  s += "b = " + column([&](int j) { return to_text(d.joints[j].b); }) + "\n";
  s += "d = " + column([&](int j) { return to_text(d.joints[j].d); }) + "\n";
  s += "r = " + column([&](int j) { return to_text(d.joints[j].r); }) + "\n";
  s += "gamma = " + column([&](int j) { return to_text(d.joints[j].gamma); }) + "\n";
  s += "alpha = " + column([&](int j) { return to_text(d.joints[j].alpha); }) + "\n";
  s += "mu = " + column([&](int j) { return std::to_string(d.joints[j].mu); }) + "\n";
  s += "theta = " + column([&](int j) { return to_text(d.joints[j].theta); }) + "\n";
  s += "\n(* Dynamic parameters and external forces *)\n";
  for (int k = 0; k < 10; ++k)
    s += std::string(kInertialFamilies[k]) + " = " + column([&](int j) { return node_text(g, links[j].inertial[k]); }) +
         "\n";
  s += "IA = " + column([&](int j) { return node_text(g, links[j].ia); }) + "\n";
  s += "FV = " + column([&](int j) { return node_text(g, links[j].fv); }) + "\n";
  s += "FS = " + column([&](int j) { return node_text(g, links[j].fs); }) + "\n";
  for (const char* f : {"FX", "FY", "FZ", "CX", "CY", "CZ"}) s += std::string(f) + " = " + zeros(d.n) + "\n";
  s += "\n(* Joint parameters *)\neta = " + zeros(d.n) + "\nk = " + zeros(d.n) + "\n";
  s += "QP = " + column([&](int j) { return d.joints[j].qd; }) + "\n";
  s += "QDP = " + column([&](int j) { return d.joints[j].qdd; }) + "\n";
  s += "GAM = " + column([&](int j) { return d.joints[j].tau; }) + "\n";
  s += "\n(* Velocity and acceleration of the base *)\nW0 = " + zeros(3) + "\nWP0 = " + zeros(3) +
       "\nV0 = " + zeros(3) + "\nVP0 = " + zeros(3) + "\n\n(* Acceleration of gravity *)\nG = {" +
       to_text(d.gravity_expr[0]) + "," + to_text(d.gravity_expr[1]) + "," + to_text(d.gravity_expr[2]) + "}\n";
  s += "\n(* Transformation of 0 frame position fT0 *)\nZ = {1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1}\n\n(* End of definition "
       "*)\n";
  return s;
}

}  // namespace

namespace {
// The solution x of A x = b, A symmetric positive definite as symbols, by LDL^T: one division
// per pivot. b(i) makes the right-hand side's row i when the forward substitution reaches it (the
// graph's nodes are made in the order the emitted text depends on).
std::vector<NodeId> ldlt_solve(ExprGraph& g, const std::vector<std::vector<NodeId>>& A,
                               const std::function<NodeId(int)>& b) {
  const int n = static_cast<int>(A.size());
  std::vector<std::vector<NodeId>> L(n, std::vector<NodeId>(n, g.zero()));
  std::vector<NodeId> D(n), inv_D(n), x(n);
  for (int j = 0; j < n; ++j) {
    NodeId dj = A[j][j];
    for (int k = 0; k < j; ++k) dj = g.sub(dj, g.mul(g.pow(L[j][k], 2.0), D[k]));
    D[j] = dj;
    inv_D[j] = g.div(g.one(), dj);
    for (int i = j + 1; i < n; ++i) {
      NodeId v = A[i][j];
      for (int k = 0; k < j; ++k) v = g.sub(v, g.mul(g.mul(L[i][k], L[j][k]), D[k]));
      L[i][j] = g.mul(v, inv_D[j]);
    }
  }
  for (int i = 0; i < n; ++i) {
    NodeId y = b(i);
    for (int k = 0; k < i; ++k) y = g.sub(y, g.mul(L[i][k], x[k]));
    x[i] = y;
  }
  for (int i = 0; i < n; ++i) x[i] = g.mul(x[i], inv_D[i]);
  for (int i = n - 1; i >= 0; --i)
    for (int k = i + 1; k < n; ++k) x[i] = g.sub(x[i], g.mul(L[k][i], x[k]));
  return x;
}

// fgm.txt and jac.txt: the pose and the Jacobian of `frame`.
void add_geometric_files(ExprGraph& g, const Description& d, Tables& t, int frame, const std::vector<std::string>& q,
                         Modeling& out) {
  const int n = d.n;
  {
    const auto T = frame_pose(g, d, frame);
    std::vector<std::pair<std::string, NodeId>> o;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 3; ++r)
        o.emplace_back("T0T" + std::to_string(frame) + std::to_string(r + 1) + std::to_string(c + 1), T[r][c]);
    out.files.push_back({"fgm.txt", model_file({"Direct Geometric model (symoroc model)"}, t.geometric(),
                                               equations_text(g, o, q, "T"))});
  }
  {
    const auto J = frame_jacobian(g, d, frame);
    std::vector<std::pair<std::string, NodeId>> o;
    for (int c = 0; c < n; ++c)
      for (int r = 0; r < 6; ++r) o.emplace_back("J" + std::to_string(r + 1) + std::to_string(c + 1), J[r][c]);
    out.files.push_back(
        {"jac.txt", model_file({"Jacobian matrix for frame " + std::to_string(frame) + " (symoroc model)",
                                "Projection frame 0, intermediate frame " + std::to_string(frame)},
                               t.geometric(), equations_text(g, o, q, "T"))});
  }
}

Modeling model_from_par_file(const grammar::ParFile& par, const ModelingOptions& options);
}  // namespace

Modeling model_from_par(const std::string& par_path, const ModelingOptions& options) {
  return model_from_par_file(grammar::read_par_file(par_path), options);
}

Modeling model_from_par_text(const std::string& text, const std::string& path, const ModelingOptions& options) {
  return model_from_par_file(grammar::parse_par_file(text, path), options);
}

Modeling model_from_urdf(const std::string& urdf_path, const ModelingOptions& options) {
  const UrdfChain chain = read_urdf_chain(urdf_path, options);
  Modeling m = model_from_par_text(chain.par_text, chain.name + ".par", options);
  m.files.insert(m.files.begin(), {{chain.name + ".par", chain.par_text}, {"robot.yaml", chain.robot_yaml}});
  m.notes.insert(m.notes.begin(), chain.notes.begin(), chain.notes.end());
  return m;
}

namespace {

Modeling model_from_par_file(const grammar::ParFile& par, const ModelingOptions& options) {
  const std::string& par_path = par.path;
  ExprGraph g;
  const Description d = read_description(g, par);
  const BaseParameters base = base_parameters(g, d);
  const int n = d.n;
  const int frame = options.frame == 0 ? n : options.frame;
  if (frame < 1 || frame > n)
    throw InputError(
        par_path, 0, 0,
        "frame " + std::to_string(options.frame) + " does not exist (the robot has " + std::to_string(n) + ")");
  Tables t{g, d};
  const std::string tables = t.dynamic(base.links);
  std::vector<std::string> q;
  for (const auto& j : d.joints) q.push_back(j.q);

  Modeling out;
  out.robot = d.name;
  out.base_parameters = base.names;
  out.notes = base.notes;
  out.files.push_back({d.name + "_base.par", base_par(g, d, base.links)});

  // regp.txt: the definitions of the base parameters over the standard ones.
  {
    std::string eq;
    for (const auto& [name, value] : base.definitions) eq += name + " = " + node_text(g, value) + ";\n";
    std::string text = "Base Inertial Parameters equations\n\n" + t.dynamic(d.links) + "Equations:\n" + eq + "*=*\n\n";
    text += "Grouped inertial parameters\n\n" + t.geometric() + t.inertia(base.links) + "*=*\n";
    out.files.push_back({"regp.txt", text});
  }

  const std::vector<NodeId> tau = inverse_dynamics(g, d, base.links);
  std::vector<std::pair<std::string, NodeId>> outputs;
  for (int j = 0; j < n; ++j) outputs.emplace_back(d.joints[j].tau, tau[j]);
  out.files.push_back({"idm.txt", model_file({"Inverse Dynamic Model using Newton-Euler Algorithm (symoroc model)",
                                              "Robot with rigid joints and fixed base", ""},
                                             tables, equations_text(g, outputs, q, "T"))});

  // The identification model: tau_j = sum_P DG{j}{P} P.
  {
    std::vector<std::pair<std::string, NodeId>> dg;
    std::vector<std::vector<NodeId>> columns;
    for (const auto& p : base.names) columns.push_back(differentiate(g, tau, p));
    for (int j = 0; j < n; ++j)
      for (std::size_t p = 0; p < base.names.size(); ++p)
        if (!g.is_constant(columns[p][j], 0.0))
          dg.emplace_back("DG" + std::to_string(j + 1) + base.names[p], columns[p][j]);
    out.files.push_back({"dim.txt", model_file({"Dynamic Identification Model (Newton-Euler method, symoroc model)"},
                                               tables, equations_text(g, dg, q, "T"))});
  }

  // Coriolis, centrifugal, gravity and friction torques: qdd = 0.
  std::map<std::string, NodeId> rest;
  for (const auto& j : d.joints) rest[j.qdd] = g.zero();
  const std::vector<NodeId> h = substitute(g, tau, rest);
  {
    std::vector<std::pair<std::string, NodeId>> o;
    for (int j = 0; j < n; ++j) o.emplace_back(d.joints[j].tau, h[j]);
    out.files.push_back({"ccg.txt", model_file({"Pseudo forces using Newton-Euler Algorithm (symoroc model)",
                                                "Robot with rigid joints and fixed base", ""},
                                               tables, equations_text(g, o, q, "T"))});
  }

  // The inertia matrix: A_ij = d tau_i / d qdd_j.
  std::vector<std::vector<NodeId>> A(n, std::vector<NodeId>(n));
  for (int j = 0; j < n; ++j) {
    const auto col = differentiate(g, tau, d.joints[j].qdd);
    for (int i = 0; i < n; ++i) A[i][j] = col[i];
  }
  {
    std::vector<std::pair<std::string, NodeId>> o;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j <= i; ++j) o.emplace_back("A" + std::to_string(i + 1) + std::to_string(j + 1), A[i][j]);
    out.files.push_back({"inm.txt", model_file({"Inertia matrix (derivatives of the Newton-Euler model, symoroc model)",
                                                "Robot with fixed base", ""},
                                               tables, equations_text(g, o, q, "T"))});
  }

  // The direct dynamics: M qdd = tau - h by an LDL^T factorization of M.
  {
    const std::vector<NodeId> x = ldlt_solve(g, A, [&](int i) { return g.sub(g.symbol(d.joints[i].tau), h[i]); });
    std::vector<std::pair<std::string, NodeId>> o;
    for (int j = 0; j < n; ++j) o.emplace_back(d.joints[j].qdd, x[j]);
    out.files.push_back(
        {"ddm.txt", model_file({"Direct Dynamic Model (LDL^T solve of the Newton-Euler model, symoroc model)",
                                "Robot with fixed base", ""},
                               tables, equations_text(g, o, q, "T"))});
  }

  add_geometric_files(g, d, t, frame, q, out);
  return out;
}

}  // namespace

}  // namespace symoro::codegen
