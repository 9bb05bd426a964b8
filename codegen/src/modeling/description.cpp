#include "description.hpp"

#include <cmath>
#include <set>

#include "symoro/codegen/robot_spec.hpp"

namespace symoro::codegen::modeling {

using grammar::Expr;

namespace {

[[noreturn]] void fail(const std::string& path, const grammar::Position& at, const std::string& message) {
  throw InputError(path, at.line, at.column, message);
}

bool is_zero(const Expr& e) {
  return (e.kind == Expr::Kind::Number && e.number == 0.0) || (e.kind == Expr::Kind::Negate && is_zero(e.args[0]));
}

void collect_symbols(const Expr& e, std::set<std::string>& out) {
  if (e.kind == Expr::Kind::Symbol && e.name != "pi") out.insert(e.name);
  for (const auto& a : e.args) collect_symbols(a, out);
}

// Exact value of sin (k pi / 2), or nothing when v is not such a multiple.
bool quarter_turn(double v, int& k) {
  const double x = v / (M_PI / 2);
  const double r = std::round(x);
  if (std::abs(x - r) > 1e-12) return false;
  k = static_cast<int>(std::fmod(std::fmod(r, 4.0) + 4.0, 4.0));
  return true;
}

}  // namespace

NodeId lower(ExprGraph& g, const Expr& e) {
  switch (e.kind) {
    case Expr::Kind::Number:
      return g.constant(e.number);
    case Expr::Kind::Symbol:
      return e.name == "pi" ? g.constant(M_PI) : g.symbol(e.name);
    case Expr::Kind::Negate:
      return g.neg(lower(g, e.args[0]));
    case Expr::Kind::Add:
      return g.add(lower(g, e.args[0]), lower(g, e.args[1]));
    case Expr::Kind::Subtract:
      return g.sub(lower(g, e.args[0]), lower(g, e.args[1]));
    case Expr::Kind::Multiply:
      return g.mul(lower(g, e.args[0]), lower(g, e.args[1]));
    case Expr::Kind::Divide:
      return g.div(lower(g, e.args[0]), lower(g, e.args[1]));
    case Expr::Kind::Power: {
      const NodeId b = lower(g, e.args[0]), p = lower(g, e.args[1]);
      if (!g.is_constant(p)) throw std::runtime_error("the exponent must be a constant");
      return g.pow(b, g.node(p).value);
    }
    case Expr::Kind::Call:
      if (e.args.size() == 1 && e.name == "sin") return exact_sin(g, lower(g, e.args[0]));
      if (e.args.size() == 1 && e.name == "cos") return exact_cos(g, lower(g, e.args[0]));
      throw std::runtime_error("unsupported function '" + e.name + "' in a robot description");
  }
  return g.zero();
}

NodeId exact_sin(ExprGraph& g, NodeId a) {
  int k = 0;
  if (g.is_constant(a) && quarter_turn(g.node(a).value, k)) return g.constant(k == 1 ? 1.0 : k == 3 ? -1.0 : 0.0);
  return g.sin(a);
}

NodeId exact_cos(ExprGraph& g, NodeId a) {
  int k = 0;
  if (g.is_constant(a) && quarter_turn(g.node(a).value, k)) return g.constant(k == 0 ? 1.0 : k == 2 ? -1.0 : 0.0);
  return g.cos(a);
}

std::string to_text(const Expr& e) {
  auto wrap = [](const Expr& a, bool need) { return need ? "(" + to_text(a) + ")" : to_text(a); };
  auto is_sum = [](const Expr& a) { return a.kind == Expr::Kind::Add || a.kind == Expr::Kind::Subtract; };
  switch (e.kind) {
    case Expr::Kind::Number: {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.17g", e.number);
      // The shortest text that reads back to the same double.
      for (int p = 1; p <= 17; ++p) {
        char t[32];
        std::snprintf(t, sizeof t, "%.*g", p, e.number);
        if (std::strtod(t, nullptr) == e.number) return t;
      }
      return buf;
    }
    case Expr::Kind::Symbol:
      return e.name;
    case Expr::Kind::Negate:
      return "-" + wrap(e.args[0], is_sum(e.args[0]));
    case Expr::Kind::Add:
      return to_text(e.args[0]) + " + " + to_text(e.args[1]);
    case Expr::Kind::Subtract:
      return to_text(e.args[0]) + " - " + wrap(e.args[1], is_sum(e.args[1]));
    case Expr::Kind::Multiply:
      return wrap(e.args[0], is_sum(e.args[0])) + "*" + wrap(e.args[1], is_sum(e.args[1]));
    case Expr::Kind::Divide:
      return wrap(e.args[0], is_sum(e.args[0])) + "/" +
             wrap(e.args[1], e.args[1].kind != Expr::Kind::Number && e.args[1].kind != Expr::Kind::Symbol &&
                                 e.args[1].kind != Expr::Kind::Call);
    case Expr::Kind::Power:
      return wrap(e.args[0], e.args[0].kind != Expr::Kind::Symbol && e.args[0].kind != Expr::Kind::Number) + "**" +
             wrap(e.args[1], e.args[1].kind != Expr::Kind::Number);
    case Expr::Kind::Call: {
      std::string s = e.name + "(";
      for (std::size_t i = 0; i < e.args.size(); ++i) s += (i ? ", " : "") + to_text(e.args[i]);
      return s + ")";
    }
  }
  return "";
}

namespace {

// The .par file's entries, read with their checks: each error names the file, line and entry.
class DescriptionReader {
 public:
  DescriptionReader(ExprGraph& g, const grammar::ParFile& par) : g_(g), par_(par) {
    for (const auto& e : par.entries) entries_[e.name] = &e;
  }

  Description read() {
    Description d;
    d.path = par_.path;
    read_sizes(d);
    d.name = par_.robot_name;
    if (d.name.empty()) {
      const auto slash = par_.path.find_last_of('/');
      d.name = par_.path.substr(slash == std::string::npos ? 0 : slash + 1);
      if (d.name.size() > 4 && d.name.compare(d.name.size() - 4, 4, ".par") == 0) d.name.resize(d.name.size() - 4);
    }
    read_joints(d);
    read_base(d);
    d.geometric_symbols.assign(geometric_.begin(), geometric_.end());
    read_standard_parameters(d);
    return d;
  }

 private:
  const grammar::ParEntry& entry(const std::string& name) const {
    auto it = entries_.find(name);
    if (it == entries_.end()) throw InputError(par_.path, 0, 0, "missing entry '" + name + "'");
    return *it->second;
  }
  bool has(const std::string& name) const { return entries_.count(name) > 0; }
  double number(const Expr& e, const std::string& what) {
    const NodeId v = lower(g_, e);
    if (!g_.is_constant(v)) fail(par_.path, e.at, "'" + what + "' must be a number");
    return g_.node(v).value;
  }
  int integer(const std::string& name) {
    const auto& e = entry(name);
    if (e.is_list || e.values.size() != 1) fail(par_.path, e.at, "'" + name + "' must be one number");
    const double v = number(e.values[0], name);
    if (v != std::floor(v) || v < 0 || v > 64) fail(par_.path, e.at, "'" + name + "' must be a whole number up to 64");
    return static_cast<int>(v);
  }
  const std::vector<Expr>& list(const std::string& name, std::size_t size) const {
    const auto& e = entry(name);
    if (!e.is_list || e.values.size() != size)
      fail(par_.path, e.at, "'" + name + "' must be a list of " + std::to_string(size) + " values");
    return e.values;
  }
  std::string symbol(const Expr& e, const std::string& what) const {
    if (e.kind != Expr::Kind::Symbol || e.name == "pi")
      fail(par_.path, e.at, "the joint variable in '" + what + "' must be a plain symbol");
    return e.name;
  }

  // NJ (= NL = NF: serial and tree robots), a fixed base, no closed loop.
  void read_sizes(Description& d) {
    d.n = integer("NJ");
    const int n = d.n;
    if (n < 1) fail(par_.path, entry("NJ").at, "NJ must be at least 1");
    if (integer("NL") != n || integer("NF") != n)
      fail(par_.path, entry("NF").at, "only serial and tree robots with NL = NJ = NF are supported");
    if (has("Type") && integer("Type") == 2)
      fail(par_.path, entry("Type").at, "closed-loop robots (Type = 2) are not supported");
    for (const char* flag : {"is_floating", "is_mobile"}) {
      if (!has(flag)) continue;
      const auto& e = entry(flag);
      if (e.values.size() != 1 || e.values[0].kind != Expr::Kind::Symbol || e.values[0].name != "False")
        fail(par_.path, e.at, std::string(flag) + " must be False: only fixed-base robots are supported");
    }
  }

  // Each joint's antecedent, type, MDH parameters (lowered) and variables; the geometric symbols.
  void read_joints(Description& d) {
    ExprGraph& g = g_;
    const int n = d.n;
    const auto &ant = list("ant", n), &sigma = list("sigma", n), &mu = list("mu", n), &gamma = list("gamma", n),
               &b = list("b", n), &alpha = list("alpha", n), &dd = list("d", n), &theta = list("theta", n),
               &r = list("r", n), &qp = list("QP", n), &qdp = list("QDP", n), &gam = list("GAM", n);
    for (int j = 0; j < n; ++j) {
      JointDescription jd;
      jd.ant = static_cast<int>(number(ant[j], "ant"));
      jd.sigma = static_cast<int>(number(sigma[j], "sigma"));
      jd.mu = static_cast<int>(number(mu[j], "mu"));
      if (jd.ant < 0 || jd.ant > j || jd.ant != number(ant[j], "ant"))
        fail(par_.path, ant[j].at, "ant of joint " + std::to_string(j + 1) + " must name an earlier frame");
      if (jd.sigma != 0 && jd.sigma != 1)
        fail(par_.path, sigma[j].at,
             "joint " + std::to_string(j + 1) +
                 ": sigma must be 0 (revolute) or 1 (prismatic); fixed joints are not supported");
      jd.gamma = gamma[j];
      jd.b = b[j];
      jd.alpha = alpha[j];
      jd.d = dd[j];
      jd.theta = theta[j];
      jd.r = r[j];
      jd.q = symbol(jd.sigma == 0 ? theta[j] : r[j], jd.sigma == 0 ? "theta" : "r");
      jd.qd = symbol(qp[j], "QP");
      jd.qdd = symbol(qdp[j], "QDP");
      jd.tau = symbol(gam[j], "GAM");
      for (const auto& s : {jd.q, jd.qd, jd.qdd, jd.tau})
        if (!names_.insert(s).second) fail(par_.path, entry("QP").at, "the joint symbol '" + s + "' appears twice");
      for (const Expr* e : {&gamma[j], &b[j], &alpha[j], &dd[j], jd.sigma == 0 ? &r[j] : &theta[j]}) {
        collect_symbols(*e, geometric_);
        std::set<std::string> used;
        collect_symbols(*e, used);
        for (const auto& s : used)
          if (names_.count(s))
            fail(par_.path, e->at, "the joint variable '" + s + "' appears in a constant geometric parameter");
      }
      try {
        jd.gamma_n = lower(g, gamma[j]);
        jd.b_n = lower(g, b[j]);
        jd.alpha_n = lower(g, alpha[j]);
        jd.d_n = lower(g, dd[j]);
        jd.theta_n = lower(g, theta[j]);
        jd.r_n = lower(g, r[j]);
      } catch (const std::runtime_error& e) {
        fail(par_.path, theta[j].at, std::string("joint ") + std::to_string(j + 1) + ": " + e.what());
      }
      d.joints.push_back(jd);
    }
  }

  // Gravity, and a fixed base at rest without flexible joints or external forces.
  void read_base(Description& d) {
    const int n = d.n;
    const auto& gl = list("G", 3);
    d.gravity_expr = gl;
    for (int i = 0; i < 3; ++i) {
      collect_symbols(gl[i], geometric_);
      d.gravity[i] = lower(g_, gl[i]);
    }
    for (const char* zero_list : {"W0", "WP0", "V0", "VP0"})
      for (const auto& e : list(zero_list, 3))
        if (!is_zero(e)) fail(par_.path, e.at, std::string(zero_list) + ": only a fixed base at rest is supported");
    for (const char* zero_list : {"eta", "k", "FX", "FY", "FZ", "CX", "CY", "CZ"}) {
      if (!has(zero_list)) continue;
      for (const auto& e : list(zero_list, n))
        if (!is_zero(e))
          fail(par_.path, e.at, std::string(zero_list) + ": flexible joints and external forces are not supported");
    }
  }

  // Each link's standard parameters: a symbol (named once) or 0.
  void read_standard_parameters(Description& d) {
    const int n = d.n;
    d.links.resize(n);
    auto parameter = [&](const char* family, int j) {
      const Expr& e = list(family, n)[j];
      if (is_zero(e)) return g_.zero();
      if (e.kind != Expr::Kind::Symbol || e.name == "pi")
        fail(par_.path, e.at,
             std::string("a standard parameter must be a symbol or 0 (") + family + " of link " +
                 std::to_string(j + 1) + ")");
      if (!names_.insert(e.name).second || geometric_.count(e.name))
        fail(par_.path, e.at, "the parameter '" + e.name + "' appears twice");
      d.standard.push_back(e.name);
      return g_.symbol(e.name);
    };
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < 10; ++k) d.links[j].inertial[k] = parameter(kInertialFamilies[k], j);
      d.links[j].ia = parameter("IA", j);
      d.links[j].fv = parameter("FV", j);
      d.links[j].fs = parameter("FS", j);
    }
  }

  ExprGraph& g_;
  const grammar::ParFile& par_;
  std::map<std::string, const grammar::ParEntry*> entries_;
  std::set<std::string> geometric_;  // the symbols of the geometry and gravity
  std::set<std::string> names_;      // the joint variables and standard parameters named so far
};

}  // namespace

Description read_description(ExprGraph& g, const grammar::ParFile& par) { return DescriptionReader(g, par).read(); }

}  // namespace symoro::codegen::modeling
