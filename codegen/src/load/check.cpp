// load_robot's second stage: what the .par and the DIM's parameter tables say, checked against
// each other and robot.yaml. Nothing here touches the expression graph; every refusal names the
// file and, where there is one, the entry's position.
#include <cmath>
#include <map>
#include <set>

#include "par_reader.hpp"
#include "stages.hpp"

namespace symoro::codegen::load {

using grammar::Expr;

namespace {

bool is_zero_constant(const Expr& e) {
  return (e.kind == Expr::Kind::Number && e.number == 0.0) ||
         (e.kind == Expr::Kind::Negate && is_zero_constant(e.args[0]));
}

std::string joint_symbol(const std::string& par_path, const Expr& e, const char* what) {
  if (e.kind != Expr::Kind::Symbol)
    fail_at(par_path, e.at, std::string("the joint variable in '") + what + "' must be a plain symbol");
  return e.name;
}

// The robot's kind: serial or tree, fixed base, NJ joints as robot.yaml lists, and every
// variant effect on one of them. Sets m.n.
void check_structure(const ParReader& pr, const std::string& par_path, RobotModel& m) {
  const int n = pr.integer("NJ");
  if (n < 1 || n > 64) fail_at(par_path, pr.entry("NJ").at, "NJ must be between 1 and 64");
  if (pr.integer("NL") != n || pr.integer("NF") != n)
    fail_at(par_path, pr.entry("NF").at, "only serial and tree robots with NL = NJ = NF are supported");
  if (pr.has("Type") && pr.integer("Type") == 2)
    fail_at(par_path, pr.entry("Type").at, "closed-loop robots (Type = 2) are not supported");
  for (const char* flag : {"is_floating", "is_mobile"}) {
    if (!pr.has(flag)) continue;
    const auto& e = pr.entry(flag);
    if (e.values.size() != 1 || e.values[0].kind != Expr::Kind::Symbol || e.values[0].name != "False")
      fail_at(par_path, e.at, std::string(flag) + " must be False: only fixed-base robots are supported");
  }
  m.n = n;
  if (static_cast<int>(m.spec.joints.size()) != n)
    throw InputError(m.spec.path, 0, 0,
                     "robot.yaml lists " + std::to_string(m.spec.joints.size()) + " joints but " + par_path +
                         " has NJ = " + std::to_string(n));
  // robot_spec.cpp leaves these to here: only the .par knows the number of joints.
  for (const auto& v : m.spec.variants)
    for (const auto& e : v.effects)
      if (e.index > n) {
        const std::string what = effect_on_links(e.kind) ? "link" : "joint";
        throw InputError(m.spec.path, e.line, e.column,
                         "variant " + v.name + ", effect " + effect_name(e.kind) + ": " + what + " " +
                             std::to_string(e.index) + " is out of range (the robot has " + std::to_string(n) + " " +
                             what + "s)");
      }
}

// The modified DH frames and the joint symbols: q from theta or r by the joint's type, then qd,
// qdd and tau from QP, QDP and GAM.
void read_frames(const ParReader& pr, const std::string& par_path, RobotModel& m) {
  const int n = m.n;
  const auto &ant = pr.list("ant", n), &sigma = pr.list("sigma", n), &mu = pr.list("mu", n),
             &gamma = pr.list("gamma", n), &b = pr.list("b", n), &alpha = pr.list("alpha", n), &d = pr.list("d", n),
             &theta = pr.list("theta", n), &r = pr.list("r", n);
  for (int j = 0; j < n; ++j) {
    Frame f;
    f.ant = static_cast<int>(pr.value(ant[j]));
    f.sigma = static_cast<int>(pr.value(sigma[j]));
    f.mu = static_cast<int>(pr.value(mu[j]));
    if (f.ant < 0 || f.ant > j) fail_at(par_path, ant[j].at, "ant must name an earlier frame");
    if (f.sigma != 0 && f.sigma != 1)
      fail_at(par_path, sigma[j].at, "sigma must be 0 (revolute) or 1 (prismatic); fixed joints are not supported");
    f.gamma = pr.value(gamma[j]);
    f.b = pr.value(b[j]);
    f.alpha = pr.value(alpha[j]);
    f.d = pr.value(d[j]);
    if (f.sigma == 0) {
      m.q.push_back(joint_symbol(par_path, theta[j], "theta"));
      f.r = pr.value(r[j]);
    } else {
      m.q.push_back(joint_symbol(par_path, r[j], "r"));
      f.theta = pr.value(theta[j]);
    }
    m.frames.push_back(f);
  }
  auto symbols = [&](const char* name) {
    std::vector<std::string> out;
    for (const auto& e : pr.list(name, n)) out.push_back(joint_symbol(par_path, e, name));
    return out;
  };
  m.qd = symbols("QP");
  m.qdd = symbols("QDP");
  m.tau = symbols("GAM");
}

// Gravity, and the entries the generated models assume zero: a base at rest, rigid joints, no
// external forces.
void read_gravity_and_check_rest(const ParReader& pr, const std::string& par_path, RobotModel& m) {
  const auto& g = pr.list("G", 3);
  for (int i = 0; i < 3; ++i) m.gravity[i] = pr.value(g[i]);
  for (const char* zero_list : {"W0", "WP0", "V0", "VP0"})
    for (const auto& e : pr.list(zero_list, 3))
      if (pr.value(e) != 0.0)
        fail_at(par_path, e.at, std::string(zero_list) + ": only a fixed base at rest is supported");
  for (const char* zero_list : {"eta", "k", "FX", "FY", "FZ", "CX", "CY", "CZ"}) {
    if (!pr.has(zero_list)) continue;
    for (const auto& e : pr.list(zero_list, m.n))
      if (!is_zero_constant(e))
        fail_at(par_path, e.at, std::string(zero_list) + ": flexible joints and external forces are not supported");
  }
}

// A parameter's unit: robot.yaml's, or its prismatic unit for the per-joint families of a
// prismatic joint.
std::string unit_of(const RobotModel& m, const std::string& family, int joint) {
  const bool per_joint = family == "IA" || family == "FV" || family == "FS";
  if (per_joint && m.frames[joint - 1].sigma == 1) return m.spec.prismatic_units.at(family);
  return m.spec.units.at(family);
}

// Standard parameters: the symbolic entries of the .par, link by link; robot.yaml's nominal
// values must name them.
std::set<std::string> read_standard_parameters(const ParReader& pr, const std::string& par_path, RobotModel& m) {
  std::set<std::string> standard_names;
  for (int j = 0; j < m.n; ++j) {
    for (const auto& fam : kFamilies) {
      const Expr& e = pr.list(fam, m.n)[j];
      if (e.kind == Expr::Kind::Symbol) {
        if (!standard_names.insert(e.name).second)
          fail_at(par_path, e.at, "standard parameter '" + e.name + "' appears twice");
        m.standard.push_back({e.name, fam, j + 1, unit_of(m, fam, j + 1)});
      } else if (!is_zero_constant(e)) {
        fail_at(par_path, e.at, "a standard parameter must be a symbol or 0");
      }
    }
  }
  for (const auto& [name, value] : m.spec.nominal)
    if (!standard_names.count(name))
      throw InputError(m.spec.path, 0, 0, "nominal: '" + name + "' is not a standard parameter of " + par_path);
  return standard_names;
}

const grammar::Table* find_table(const grammar::ModelFile& f, const std::string& title) {
  for (const auto& t : f.tables)
    if (t.title == title) return &t;
  return nullptr;
}

int column_of(const grammar::Table& t, const std::string& name) {
  for (std::size_t i = 0; i < t.columns.size(); ++i)
    if (t.columns[i] == name) return static_cast<int>(i);
  return -1;
}

// Base parameters: the symbolic cells of the DIM's parameter tables, put in canonical order
// (link inertial parameters link by link, then joint parameters family by family).
std::set<std::string> read_base_parameters(const grammar::ModelFile& dim, RobotModel& m) {
  const int n = m.n;
  const grammar::Table* inertia_table = find_table(dim, "Dynamic inertia parameters");
  const grammar::Table* joint_table = find_table(dim, "External forces and joint parameters");
  if (!inertia_table || !joint_table)
    throw InputError(dim.path, dim.equations_at.line, 1,
                     "missing the 'Dynamic inertia parameters' or 'External forces and joint parameters' table");
  std::map<std::pair<std::string, int>, ParameterRef> by_slot;
  std::set<std::string> base_names;
  auto collect = [&](const grammar::Table& t, const std::string& fam) {
    const int col = column_of(t, fam);
    if (col < 0) fail_at(dim.path, t.at, "table '" + t.title + "' has no column " + fam);
    if (static_cast<int>(t.rows.size()) != n)
      fail_at(dim.path, t.at,
              "table '" + t.title + "' has " + std::to_string(t.rows.size()) + " rows for " + std::to_string(n) +
                  " joints");
    for (int j = 0; j < n; ++j) {
      const Expr& cell = t.rows[j].cells[col];
      if (cell.kind == Expr::Kind::Symbol) {
        if (!base_names.insert(cell.name).second)
          fail_at(dim.path, cell.at, "base parameter '" + cell.name + "' appears twice");
        by_slot[{fam, j + 1}] = {cell.name, fam, j + 1, unit_of(m, fam, j + 1)};
      } else if (!is_zero_constant(cell)) {
        fail_at(dim.path, cell.at, "a parameter cell must be a symbol or 0");
      }
    }
  };
  for (const auto& fam : kFamilies) collect(fam == "FV" || fam == "FS" ? *joint_table : *inertia_table, fam);
  for (int j = 1; j <= n; ++j)  // link inertial parameters, link by link
    for (std::size_t f = 0; f < 10; ++f)
      if (auto it = by_slot.find({kFamilies[f], j}); it != by_slot.end()) m.base.push_back(it->second);
  for (const char* fam : {"IA", "FV", "FS"})  // then joint parameters, family by family
    for (int j = 1; j <= n; ++j)
      if (auto it = by_slot.find({fam, j}); it != by_slot.end()) m.base.push_back(it->second);
  return base_names;
}

}  // namespace

ParameterNames check_robot(const RobotFiles& files, RobotModel& m) {
  const ParReader pr(files.par, m.spec.constants);
  check_structure(pr, files.par_path, m);
  read_frames(pr, files.par_path, m);
  read_gravity_and_check_rest(pr, files.par_path, m);
  ParameterNames names;
  names.standard = read_standard_parameters(pr, files.par_path, m);
  names.base = read_base_parameters(files.dim, m);
  // A constant is replaced by its value when lowering, so it cannot also be a parameter.
  for (const auto& c : m.spec.constants)
    if (names.base.count(c.first) || names.standard.count(c.first))
      throw InputError(m.spec.path, 0, 0, "constant '" + c.first + "' is also a parameter name");
  return names;
}

}  // namespace symoro::codegen::load
