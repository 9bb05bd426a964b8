#include "symoro/codegen/robot_model.hpp"

#include "symoro/codegen/source_digest.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <regex>
#include <set>

#include "symoro/grammar/evaluate.hpp"
#include "symoro/grammar/parser.hpp"

namespace symoro::codegen {

namespace fs = std::filesystem;
using grammar::Expr;

namespace {

[[noreturn]] void fail_at(const std::string& file, const grammar::Position& at,
                          const std::string& message) {
  throw InputError(file, at.line, at.column, message);
}

// The entries of a .par file by name, with typed accessors that report precise errors.
class ParReader {
 public:
  ParReader(const grammar::ParFile& par, const std::map<std::string, double>& constants)
      : par_(par) {
    for (const auto& e : par.entries) entries_[e.name] = &e;
    for (const auto& [k, v] : constants) bindings_[k] = v;
  }

  const grammar::ParEntry& entry(const std::string& name) const {
    auto it = entries_.find(name);
    if (it == entries_.end())
      throw InputError(par_.path, 0, 0, "missing entry '" + name + "'");
    return *it->second;
  }
  bool has(const std::string& name) const { return entries_.count(name) > 0; }

  const std::vector<Expr>& list(const std::string& name, std::size_t size) const {
    const auto& e = entry(name);
    if (!e.is_list || e.values.size() != size)
      fail_at(par_.path, e.at, "'" + name + "' must be a list of " + std::to_string(size) + " values");
    return e.values;
  }

  double value(const Expr& e) const {
    try {
      return grammar::evaluate(e, bindings_);
    } catch (const std::runtime_error& err) {
      fail_at(par_.path, e.at, std::string(err.what()) +
                                   " (geometric constants take their values from robot.yaml 'constants')");
    }
  }

  int integer(const std::string& name) const {
    const auto& e = entry(name);
    if (e.is_list || e.values.size() != 1) fail_at(par_.path, e.at, "'" + name + "' must be one number");
    const double v = value(e.values[0]);
    if (v != std::floor(v) || v < 0 || v > 10000) fail_at(par_.path, e.at, "'" + name + "' must be a whole number");
    return static_cast<int>(v);
  }

  const std::string& path() const { return par_.path; }

 private:
  const grammar::ParFile& par_;
  std::map<std::string, const grammar::ParEntry*> entries_;
  grammar::Bindings bindings_;
};

bool is_zero_constant(const Expr& e) {
  return (e.kind == Expr::Kind::Number && e.number == 0.0) ||
         (e.kind == Expr::Kind::Negate && is_zero_constant(e.args[0]));
}

// Lowers parsed equations into the graph, one file at a time.
class Lowering {
 public:
  Lowering(ExprGraph& g, const std::map<std::string, double>& constants) : g_(g) {
    for (const auto& [k, v] : constants) constants_[k] = g.constant(v);
    constants_.emplace("pi", g.constant(M_PI));
  }

  // Runs the file's equations. `inputs` are the symbols it may use besides earlier equations;
  // `role` says what the file computes, for messages. Returns name -> node after the last line.
  std::map<std::string, NodeId> run(const grammar::ModelFile& file, const std::set<std::string>& inputs,
                                    const std::string& role) {
    std::map<std::string, NodeId> env;
    for (const auto& eq : file.equations) env[eq.name] = lower(eq.value, env, inputs, file.path, role);
    return env;
  }

 private:
  NodeId leaf(const Expr& e, const std::map<std::string, NodeId>& env,
              const std::set<std::string>& inputs, const std::string& path, const std::string& role) {
    if (auto it = env.find(e.name); it != env.end()) return it->second;
    if (inputs.count(e.name)) return g_.symbol(e.name);
    if (auto it = constants_.find(e.name); it != constants_.end()) return it->second;
    fail_at(path, e.at, "unknown symbol '" + e.name + "': not defined by an earlier equation, not an input of the " +
                            role + ", and not a constant in robot.yaml");
  }

  // Post-order walk with an explicit stack: long operator chains make deep trees.
  NodeId lower(const Expr& root, const std::map<std::string, NodeId>& env,
               const std::set<std::string>& inputs, const std::string& path, const std::string& role) {
    struct Item {
      const Expr* e;
      std::size_t next;
    };
    std::vector<Item> stack{{&root, 0}};
    std::vector<NodeId> values;
    while (!stack.empty()) {
      const Expr* e = stack.back().e;
      if (stack.back().next < e->args.size()) {
        const Expr* child = &e->args[stack.back().next++];
        stack.push_back({child, 0});
        continue;
      }
      stack.pop_back();
      const std::size_t k = e->args.size();
      const NodeId* a = values.data() + (values.size() - k);
      NodeId out = -1;
      switch (e->kind) {
        case Expr::Kind::Number: out = g_.constant(e->number); break;
        case Expr::Kind::Symbol: out = leaf(*e, env, inputs, path, role); break;
        case Expr::Kind::Negate: out = g_.neg(a[0]); break;
        case Expr::Kind::Add: out = g_.add(a[0], a[1]); break;
        case Expr::Kind::Subtract: out = g_.sub(a[0], a[1]); break;
        case Expr::Kind::Multiply: out = g_.mul(a[0], a[1]); break;
        case Expr::Kind::Divide: out = g_.div(a[0], a[1]); break;
        case Expr::Kind::Power:
          if (!g_.is_constant(a[1])) fail_at(path, e->args[1].at, "the exponent must be a constant");
          out = g_.pow(a[0], g_.node(a[1]).value);
          break;
        case Expr::Kind::Call:
          if (k != 1) fail_at(path, e->at, "'" + e->name + "' takes one argument");
          if (e->name == "sin") out = g_.sin(a[0]);
          else if (e->name == "cos") out = g_.cos(a[0]);
          else if (e->name == "sign") out = g_.sign(a[0]);
          else fail_at(path, e->at, "unknown function '" + e->name + "' (supported: sin, cos, sign)");
          break;
      }
      values.resize(values.size() - k);
      values.push_back(out);
    }
    return values.back();
  }

  ExprGraph& g_;
  std::map<std::string, NodeId> constants_;
};

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

NodeId lookup_or_zero(const ExprGraph& g, const std::map<std::string, NodeId>& env,
                      const std::string& name) {
  auto it = env.find(name);
  return it == env.end() ? g.zero() : it->second;
}

}  // namespace

RobotModel load_robot(const std::string& dir_in) {
  RobotModel m;
  const fs::path dir = fs::path(dir_in).lexically_normal();
  m.dir = dir.string();
  m.name = (dir.has_filename() ? dir.filename() : dir.parent_path().filename()).string();
  static const std::regex ident("^[A-Za-z_][A-Za-z0-9_]*$");
  if (!std::regex_match(m.name, ident))
    throw InputError(m.dir, 0, 0, "the robot folder name must be a C++ identifier (it names the namespace)");
  if (!fs::is_directory(dir)) throw InputError(m.dir, 0, 0, "not a directory");

  m.spec = read_robot_spec((dir / "robot.yaml").string());

  // <robot>.par and <robot>_base.par
  std::string par_path, base_par_path;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string file = entry.path().filename().string();
    if (entry.path().extension() != ".par") continue;
    std::string& slot = file.size() > 9 && file.compare(file.size() - 9, 9, "_base.par") == 0
                            ? base_par_path : par_path;
    if (!slot.empty()) throw InputError(m.dir, 0, 0, "more than one " + std::string(&slot == &par_path ? "robot" : "base") + " .par file");
    slot = entry.path().string();
  }
  if (par_path.empty()) throw InputError(m.dir, 0, 0, "no <robot>.par description");
  if (base_par_path.empty()) throw InputError(m.dir, 0, 0, "no <robot>_base.par description");

  for (const std::string& f : {(dir / "robot.yaml").string(), par_path, base_par_path})
    m.sources.emplace_back(fs::path(f).filename().string(), file_content_digest(f));
  for (const char* f : {"dim.txt", "idm.txt", "ddm.txt", "inm.txt", "ccg.txt", "fgm.txt", "jac.txt", "regp.txt"})
    if (fs::exists(dir / f)) m.sources.emplace_back(f, file_content_digest((dir / f).string()));
  std::sort(m.sources.begin(), m.sources.end());
  const auto par = grammar::read_par_file(par_path);
  grammar::read_par_file(base_par_path);  // checked for syntax; the model files carry its content
  auto read = [&](const char* f) { return grammar::read_model_file((dir / f).string()); };
  const auto dim = read("dim.txt"), idm = read("idm.txt"), ddm = read("ddm.txt"),
             inm = read("inm.txt"), ccg = read("ccg.txt"), fgm = read("fgm.txt"),
             jac = read("jac.txt"), regp = read("regp.txt");

  // ---- the robot description
  ParReader pr(par, m.spec.constants);
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
    throw InputError(m.spec.path, 0, 0, "robot.yaml lists " + std::to_string(m.spec.joints.size()) +
                                            " joints but " + par_path + " has NJ = " + std::to_string(n));
  for (const auto& v : m.spec.variants)
    for (const auto& e : v.effects)
      if (e.index > n) {
        const std::string what = effect_on_links(e.kind) ? "link" : "joint";
        throw InputError(m.spec.path, e.line, e.column,
                         "variant " + v.name + ", effect " + effect_name(e.kind) + ": " + what + " " +
                             std::to_string(e.index) + " is out of range (the robot has " + std::to_string(n) + " " +
                             what + "s)");
      }

  const auto &ant = pr.list("ant", n), &sigma = pr.list("sigma", n), &mu = pr.list("mu", n),
             &gamma = pr.list("gamma", n), &b = pr.list("b", n), &alpha = pr.list("alpha", n),
             &d = pr.list("d", n), &theta = pr.list("theta", n), &r = pr.list("r", n);
  auto joint_symbol = [&](const Expr& e, const char* what) {
    if (e.kind != Expr::Kind::Symbol)
      fail_at(par_path, e.at, std::string("the joint variable in '") + what + "' must be a plain symbol");
    return e.name;
  };
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
      m.q.push_back(joint_symbol(theta[j], "theta"));
      f.r = pr.value(r[j]);
    } else {
      m.q.push_back(joint_symbol(r[j], "r"));
      f.theta = pr.value(theta[j]);
    }
    m.frames.push_back(f);
  }
  auto symbols = [&](const char* name) {
    std::vector<std::string> out;
    for (const auto& e : pr.list(name, n)) out.push_back(joint_symbol(e, name));
    return out;
  };
  m.qd = symbols("QP");
  m.qdd = symbols("QDP");
  m.tau = symbols("GAM");

  const auto& g = pr.list("G", 3);
  for (int i = 0; i < 3; ++i) m.gravity[i] = pr.value(g[i]);
  for (const char* zero_list : {"W0", "WP0", "V0", "VP0"})
    for (const auto& e : pr.list(zero_list, 3))
      if (pr.value(e) != 0.0) fail_at(par_path, e.at, std::string(zero_list) + ": only a fixed base at rest is supported");
  for (const char* zero_list : {"eta", "k", "FX", "FY", "FZ", "CX", "CY", "CZ"}) {
    if (!pr.has(zero_list)) continue;
    for (const auto& e : pr.list(zero_list, n))
      if (!is_zero_constant(e))
        fail_at(par_path, e.at, std::string(zero_list) + ": flexible joints and external forces are not supported");
  }

  auto unit_of = [&](const std::string& family, int joint) {
    const bool per_joint = family == "IA" || family == "FV" || family == "FS";
    if (per_joint && m.frames[joint - 1].sigma == 1) return m.spec.prismatic_units.at(family);
    return m.spec.units.at(family);
  };

  // Standard parameters: the symbolic entries of the .par, link by link.
  std::set<std::string> standard_names;
  for (int j = 0; j < n; ++j) {
    for (const auto& fam : kFamilies) {
      const Expr& e = pr.list(fam, n)[j];
      if (e.kind == Expr::Kind::Symbol) {
        if (!standard_names.insert(e.name).second) fail_at(par_path, e.at, "standard parameter '" + e.name + "' appears twice");
        m.standard.push_back({e.name, fam, j + 1, unit_of(fam, j + 1)});
      } else if (!is_zero_constant(e)) {
        fail_at(par_path, e.at, "a standard parameter must be a symbol or 0");
      }
    }
  }

  for (const auto& [name, value] : m.spec.nominal)
    if (!standard_names.count(name))
      throw InputError(m.spec.path, 0, 0, "nominal: '" + name + "' is not a standard parameter of " + par_path);

  // ---- base parameters: the symbolic cells of the DIM's parameter tables
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
      fail_at(dim.path, t.at, "table '" + t.title + "' has " + std::to_string(t.rows.size()) + " rows for " + std::to_string(n) + " joints");
    for (int j = 0; j < n; ++j) {
      const Expr& cell = t.rows[j].cells[col];
      if (cell.kind == Expr::Kind::Symbol) {
        if (!base_names.insert(cell.name).second) fail_at(dim.path, cell.at, "base parameter '" + cell.name + "' appears twice");
        by_slot[{fam, j + 1}] = {cell.name, fam, j + 1, unit_of(fam, j + 1)};
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
  for (const auto& c : m.spec.constants)
    if (base_names.count(c.first) || standard_names.count(c.first))
      throw InputError(m.spec.path, 0, 0, "constant '" + c.first + "' is also a parameter name");

  // ---- lowering
  Lowering lower(m.graph, m.spec.constants);
  std::set<std::string> q(m.q.begin(), m.q.end()), qd(m.qd.begin(), m.qd.end()),
      qdd(m.qdd.begin(), m.qdd.end()), tau(m.tau.begin(), m.tau.end());
  auto unite = [](std::initializer_list<const std::set<std::string>*> sets) {
    std::set<std::string> out;
    for (const auto* s : sets) out.insert(s->begin(), s->end());
    return out;
  };

  {
    const auto env = lower.run(dim, unite({&q, &qd, &qdd}), "identification model (dim.txt)");
    std::set<std::string> used;
    m.dim.assign(n, std::vector<NodeId>(m.base.size(), m.graph.zero()));
    for (int j = 0; j < n; ++j)
      for (std::size_t p = 0; p < m.base.size(); ++p) {
        const std::string name = "DG" + std::to_string(j + 1) + m.base[p].name;
        m.dim[j][p] = lookup_or_zero(m.graph, env, name);
        used.insert(name);
      }
    for (const auto& eq : dim.equations)
      if (eq.name.rfind("DG", 0) == 0 && !used.count(eq.name))
        fail_at(dim.path, eq.at, "'" + eq.name + "' names no joint and base parameter of the tables");
  }
  const std::set<std::string> params(base_names.begin(), base_names.end());
  auto outputs = [&](const grammar::ModelFile& f, const std::map<std::string, NodeId>& env,
                     const std::vector<std::string>& names) {
    std::vector<NodeId> out;
    for (const auto& name : names) {
      auto it = env.find(name);
      if (it == env.end()) throw InputError(f.path, f.equations_at.line, 1, "no equation defines " + name);
      out.push_back(it->second);
    }
    return out;
  };
  m.idm = outputs(idm, lower.run(idm, unite({&q, &qd, &qdd, &params}), "inverse dynamic model (idm.txt)"), m.tau);
  m.ccg = outputs(ccg, lower.run(ccg, unite({&q, &qd, &params}), "Coriolis and gravity model (ccg.txt)"), m.tau);
  m.ddm = outputs(ddm, lower.run(ddm, unite({&q, &qd, &tau, &params}), "direct dynamic model (ddm.txt)"), m.qdd);
  {
    const auto env = lower.run(inm, unite({&q, &params}), "inertia matrix (inm.txt)");
    m.inm.assign(n, std::vector<NodeId>(n, m.graph.zero()));
    for (int i = 0; i < n; ++i)
      for (int j = 0; j <= i; ++j)
        m.inm[i][j] = m.inm[j][i] = lookup_or_zero(m.graph, env, "A" + std::to_string(i + 1) + std::to_string(j + 1));
  }
  {
    const auto env = lower.run(fgm, q, "geometric model (fgm.txt)");
    auto entry = [](int f, int r, int c) { return "T0T" + std::to_string(f) + std::to_string(r) + std::to_string(c); };
    for (int f = n; f >= 1 && m.fgm_frame == 0; --f)
      for (int r = 1; r <= 3; ++r)
        for (int c = 1; c <= 4; ++c)
          if (env.count(entry(f, r, c))) m.fgm_frame = f;
    if (m.fgm_frame == 0) throw InputError(fgm.path, fgm.equations_at.line, 1, "no equation defines a T0T<frame><row><column> entry");
    m.fgm.assign(4, std::vector<NodeId>(4, m.graph.zero()));
    for (int r = 1; r <= 3; ++r)
      for (int c = 1; c <= 4; ++c) m.fgm[r - 1][c - 1] = lookup_or_zero(m.graph, env, entry(m.fgm_frame, r, c));
    m.fgm[3][3] = m.graph.one();
  }
  {
    const auto env = lower.run(jac, q, "Jacobian (jac.txt)");
    m.jac.assign(6, std::vector<NodeId>(n, m.graph.zero()));
    for (int r = 1; r <= 6; ++r)
      for (int c = 1; c <= n; ++c)
        m.jac[r - 1][c - 1] = lookup_or_zero(m.graph, env, "J" + std::to_string(r) + std::to_string(c));
  }
  {
    const auto env = lower.run(regp, unite({&q, &standard_names}), "base parameter equations (regp.txt)");
    for (const auto& p : m.base) {
      if (auto it = env.find(p.name); it != env.end()) {
        m.base_from_standard.push_back(it->second);
      } else if (standard_names.count(p.name)) {
        m.base_from_standard.push_back(m.graph.symbol(p.name));
      } else {
        throw InputError(regp.path, regp.equations_at.line, 1,
                         "base parameter " + p.name + " is neither defined here nor a standard parameter of the .par");
      }
    }
  }
  return m;
}

}  // namespace symoro::codegen
