#include "symoro/codegen/robot_spec.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <regex>
#include <set>

#include "symoro/effect_table.hpp"
#include "yaml_check.hpp"

namespace symoro::codegen {

InputError::InputError(const std::string& file, int line, int column, const std::string& message)
    : std::runtime_error(file + ":" + std::to_string(line) + ":" + std::to_string(column) + ": error: " + message) {}

namespace {

const std::map<std::string, std::string> kDefaultUnits = {
    {"XX", "kg*m^2"}, {"XY", "kg*m^2"},    {"XZ", "kg*m^2"}, {"YY", "kg*m^2"}, {"YZ", "kg*m^2"},
    {"ZZ", "kg*m^2"}, {"MX", "kg*m"},      {"MY", "kg*m"},   {"MZ", "kg*m"},   {"M", "kg"},
    {"IA", "kg*m^2"}, {"FV", "N*m*s/rad"}, {"FS", "N*m"}};
const std::map<std::string, std::string> kDefaultPrismaticUnits = {{"IA", "kg"}, {"FV", "N*s/m"}, {"FS", "N"}};

struct Reader {
  std::string path;

  [[noreturn]] void fail(const YAML::Node& n, const std::string& message) const {
    const YAML::Mark m = n.Mark();
    throw InputError(path, m.line + 1, m.column + 1, message);
  }

  // A number, or a string "<number> deg".
  double number(const YAML::Node& n, const std::string& what) const {
    if (!n || !n.IsScalar()) fail(n, what + " must be a number");
    const std::string s = n.Scalar();
    static const std::regex deg(R"(^\s*([-+]?[0-9]*\.?[0-9]+([eE][-+]?[0-9]+)?)\s*deg\s*$)");
    std::smatch m;
    if (std::regex_match(s, m, deg)) return std::stod(m[1].str()) * M_PI / 180.0;
    try {
      std::size_t used = 0;
      const double v = std::stod(s, &used);
      if (used != s.size() || !std::isfinite(v)) fail(n, what + " must be a finite number, not '" + s + "'");
      return v;
    } catch (const std::logic_error&) {
      fail(n, what + " must be a number (or '<number> deg'), not '" + s + "'");
    }
  }

  std::string string(const YAML::Node& n, const std::string& what) const {
    if (!n || !n.IsScalar()) fail(n, what + " must be a string");
    return n.Scalar();
  }

  void only_keys(const YAML::Node& map, const std::vector<std::string>& allowed, const std::string& where) const {
    check_keys(map, allowed, path, where);
  }
};

bool is_identifier(const std::string& s) {
  static const std::regex id("^[A-Za-z_][A-Za-z0-9_]*$");
  return std::regex_match(s, id);
}

// A whole number in [lo, hi]; messages start with `where`.
int whole_number(const Reader& r, const YAML::Node& n, const std::string& what, int lo, int hi,
                 const std::string& where) {
  const double v = r.number(n, where + ": " + what);
  if (v != std::floor(v)) r.fail(n, where + ": " + what + " must be a whole number, not '" + n.Scalar() + "'");
  if (v < lo)
    r.fail(n, where + ": " + what + " " + n.Scalar() + " is out of range (at least " + std::to_string(lo) + ")");
  if (v > hi)
    r.fail(n, where + ": " + what + " " + n.Scalar() + " is out of range (at most " + std::to_string(hi) + ")");
  return static_cast<int>(v);
}

// A non-empty list of distinct whole numbers in [lo, hi], with the node of each.
std::vector<std::pair<int, YAML::Node>> whole_numbers(const Reader& r, const YAML::Node& list, const std::string& what,
                                                      int lo, int hi, const std::string& where) {
  if (!list.IsSequence() || list.size() == 0)
    r.fail(list, where + " needs a non-empty list of " + what + "s, e.g. [" + std::to_string(lo) + "]");
  std::vector<std::pair<int, YAML::Node>> out;
  for (const auto& item : list) {
    const int k = whole_number(r, item, what, lo, hi, where);
    for (const auto& [seen, node] : out)
      if (seen == k) r.fail(item, where + ": duplicate " + what + " " + std::to_string(k));
    out.emplace_back(k, item);
  }
  return out;
}

// A variant's own `effects:` map (effects.hpp has the catalogue).
// Joint (link) numbers are checked against the robot's joints by load_robot, which knows them
// from the .par: here only against the most joints a robot may have.
std::vector<EffectSpec> read_effects(const Reader& r, const YAML::Node& effects, const std::string& variant) {
  constexpr int kMaxJoints = 64;
  const std::string where = "variant " + variant;
  if (!effects.IsMap() || effects.size() == 0)
    r.fail(effects, where + ": 'effects' must map effect names (" + effect_names() + ") to joints");
  std::vector<EffectSpec> out;
  std::set<std::string> seen;
  for (const auto& kv : effects) {
    const std::string name = kv.first.Scalar();
    const auto kind = effect_kind(name);
    if (!kind) {
      std::vector<std::string> known;  // effect_names() is "a, b, ..."
      for (std::size_t at = 0, comma; at < effect_names().size(); at = comma + 2) {
        comma = std::min(effect_names().find(", ", at), effect_names().size());
        known.push_back(effect_names().substr(at, comma - at));
      }
      const std::string near = nearest_name(name, known);
      r.fail(kv.first, where + ": unknown effect '" + name + "'" +
                           (near.empty() ? "" : "; did you mean '" + near + "'?") +
                           " (known effects: " + effect_names() + ")");
    }
    if (!seen.insert(name).second) r.fail(kv.first, where + ": effect " + name + " appears twice");
    const std::string what = effect_on_links(*kind) ? "link" : "joint";
    const std::string effect = where + ", effect " + name;
    YAML::Node list;
    list.reset(kv.second);  // reset, not =: assigning a YAML::Node rebinds what it refers to
    double velocity = 0;
    std::vector<double> velocities;  // one per listed joint, when `velocity` is a list
    std::vector<int> orders;
    if (effect_has_velocity(*kind) || *kind == EffectKind::PositionHarmonics) {
      const bool stribeck = effect_has_velocity(*kind);
      const std::string what_velocity(effect_row(*kind).velocity_scale);
      const std::string form = stribeck ? "{joints: [...], velocity: <rad/s>}" : "{joints: [...], orders: [...]}";
      if (!kv.second.IsMap()) r.fail(kv.second, effect + " takes " + form);
      r.only_keys(
          kv.second,
          stribeck ? std::vector<std::string>{"joints", "velocity"} : std::vector<std::string>{"joints", "orders"},
          effect);
      list.reset(kv.second["joints"]);
      if (!list) r.fail(kv.second, effect + " needs 'joints': " + form);
      if (stribeck) {
        velocity = effect_row(*kind).default_velocity;
        if (const auto vel = kv.second["velocity"]) {
          // A number for every joint, or a list with one per joint (dynid diagnose selects a
          // tanh width per joint).
          auto positive = [&](const YAML::Node& v) {
            const double x = r.number(v, what_velocity);
            if (!(x > 0)) r.fail(v, effect + ": " + what_velocity + " must be positive (rad/s), not " + v.Scalar());
            return x;
          };
          if (vel.IsSequence()) {
            if (!list.IsSequence() || vel.size() != list.size())
              r.fail(vel, effect + ": a list of velocities needs one per joint (" + std::to_string(vel.size()) +
                              " for " + std::to_string(list.IsSequence() ? list.size() : 0) + " joints)");
            for (const auto& v : vel) velocities.push_back(positive(v));
          } else {
            velocity = positive(vel);
          }
        }
      } else {
        const auto o = kv.second["orders"];
        if (!o) r.fail(kv.second, effect + " needs 'orders': " + form);
        for (const auto& [k, node] : whole_numbers(r, o, "order", 1, 1000, effect)) orders.push_back(k);
        std::sort(orders.begin(), orders.end());
      }
    }
    std::size_t k = 0;
    for (const auto& [j, node] : whole_numbers(r, list, what, 1, kMaxJoints, effect)) {
      const YAML::Mark m = node.Mark();
      out.push_back({*kind, j, velocities.empty() ? velocity : velocities.at(k), orders, m.line + 1, m.column + 1});
      ++k;
    }
  }
  return out;
}

struct RawVariant {
  VariantSpec spec;      // its own fixed patterns and effects until resolve_bases
  YAML::Node base_node;  // `base:`, when present
};

// Prepends each variant's base chain (fixed patterns and effects) to its own, in place.
void resolve_bases(const Reader& r, std::vector<RawVariant>& raw) {
  std::vector<int> state(raw.size(), 0);  // 0 to do, 1 on the current chain, 2 resolved
  std::vector<std::string> chain;
  std::function<void(std::size_t)> resolve = [&](std::size_t i) {
    if (state[i] == 2) return;
    RawVariant& v = raw[i];
    state[i] = 1;
    chain.push_back(v.spec.name);
    if (!v.spec.base.empty()) {
      std::size_t b = 0;
      while (b < raw.size() && raw[b].spec.name != v.spec.base) ++b;
      if (b == raw.size()) {
        std::string names;
        for (const auto& o : raw) names += (names.empty() ? "" : ", ") + o.spec.name;
        r.fail(v.base_node,
               "variant " + v.spec.name + ": unknown base variant '" + v.spec.base + "' (variants: " + names + ")");
      }
      if (state[b] == 1) {
        std::string cycle;
        for (auto it = std::find(chain.begin(), chain.end(), raw[b].spec.name); it != chain.end(); ++it)
          cycle += *it + " -> ";
        r.fail(v.base_node, "variant " + v.spec.name + ": the base chain " + cycle + raw[b].spec.name + " is a cycle");
      }
      resolve(b);
      const VariantSpec& base = raw[b].spec;
      for (const auto& e : v.spec.effects)
        for (const auto& be : base.effects)
          if (be.kind == e.kind && be.index == e.index)
            throw InputError(r.path, e.line, e.column,
                             "variant " + v.spec.name + ": effect " + effect_name(e.kind) + " on " +
                                 (effect_on_links(e.kind) ? "link " : "joint ") + std::to_string(e.index) +
                                 " is already in its base variant '" + base.name + "'");
      std::vector<std::pair<std::string, double>> fixed = base.fixed;
      fixed.insert(fixed.end(), v.spec.fixed.begin(), v.spec.fixed.end());
      v.spec.fixed = fixed;
      std::vector<EffectSpec> effects = base.effects;
      effects.insert(effects.end(), v.spec.effects.begin(), v.spec.effects.end());
      v.spec.effects = effects;
    }
    chain.pop_back();
    state[i] = 2;
  };
  for (std::size_t i = 0; i < raw.size(); ++i) resolve(i);
}

}  // namespace

bool glob_match(const std::string& pattern, const std::string& name) {
  // Iterative wildcard matching with backtracking to the last '*'.
  std::size_t p = 0, n = 0, star = std::string::npos, mark = 0;
  while (n < name.size()) {
    if (p < pattern.size() && pattern[p] == name[n]) {
      ++p, ++n;
    } else if (p < pattern.size() && pattern[p] == '*') {
      star = p++, mark = n;
    } else if (star != std::string::npos) {
      p = star + 1, n = ++mark;
    } else {
      return false;
    }
  }
  while (p < pattern.size() && pattern[p] == '*') ++p;
  return p == pattern.size();
}

namespace {

// robot.yaml's `joints`: one entry per joint, named, with its limits (and its audit box).
void read_joints(const Reader& r, const YAML::Node& root, RobotSpec& spec) {
  const std::string& path = r.path;
  const auto joints = root["joints"];
  if (!joints || !joints.IsSequence() || joints.size() == 0)
    throw InputError(path, 1, 1, "missing 'joints': a list with one entry per joint");
  std::set<std::string> joint_names;
  for (const auto& j : joints) {
    if (!j.IsMap()) r.fail(j, "a joint must be a mapping (name, lower, upper, velocity, effort)");
    // torque_constant (N m/A): read by dynid import for bags whose effort is motor current.
    r.only_keys(j, {"name", "lower", "upper", "velocity", "effort", "audit", "torque_constant"}, "a joint");
    JointSpec js;
    js.name = r.string(j["name"], "joint name");
    if (!is_identifier(js.name)) r.fail(j["name"], "joint name '" + js.name + "' is not an identifier");
    if (!joint_names.insert(js.name).second) r.fail(j["name"], "duplicate joint name '" + js.name + "'");
    if (!j["lower"] || !j["upper"]) r.fail(j, "joint " + js.name + " needs 'lower' and 'upper'");
    js.lower = r.number(j["lower"], "lower");
    js.upper = r.number(j["upper"], "upper");
    if (!(js.lower < js.upper)) r.fail(j["upper"], "joint " + js.name + ": upper must exceed lower");
    if (!j["velocity"] || !j["effort"]) r.fail(j, "joint " + js.name + " needs 'velocity' and 'effort'");
    js.velocity = r.number(j["velocity"], "velocity");
    js.effort = r.number(j["effort"], "effort");
    if (js.velocity <= 0 || js.effort <= 0)
      r.fail(j, "joint " + js.name + ": velocity and effort limits must be positive");
    js.audit_lower = js.lower;
    js.audit_upper = js.upper;
    if (const auto a = j["audit"]) {
      if (!a.IsSequence() || a.size() != 2) r.fail(a, "audit must be [lower, upper]");
      js.audit_lower = r.number(a[0], "audit lower bound");
      js.audit_upper = r.number(a[1], "audit upper bound");
      if (!(js.audit_lower < js.audit_upper)) r.fail(a, "audit: upper must exceed lower");
    }
    if (const auto k = j["torque_constant"]; k && !(r.number(k, "torque_constant") > 0))
      r.fail(k, "joint " + js.name + ": torque_constant must be positive (N m/A)");
    spec.joints.push_back(js);
  }
}

// robot.yaml's `parameter_units` over the defaults, per family, for revolute and prismatic joints.
void read_units(const Reader& r, const YAML::Node& root, RobotSpec& spec) {
  spec.units = kDefaultUnits;
  spec.prismatic_units = kDefaultPrismaticUnits;
  if (const auto u = root["parameter_units"]) {
    if (!u.IsMap()) r.fail(u, "parameter_units must be a mapping (revolute, prismatic)");
    r.only_keys(u, {"revolute", "prismatic"}, "parameter_units");
    auto read = [&](const YAML::Node& m, std::map<std::string, std::string>& into) {
      if (!m) return;
      if (!m.IsMap()) r.fail(m, "units must map families (XX, MX, IA, FV, ...) to unit strings");
      for (const auto& kv : m) {
        const std::string fam = kv.first.Scalar();
        if (!kDefaultUnits.count(fam)) {
          std::vector<std::string> known;
          for (const auto& [f, unit] : kDefaultUnits) known.push_back(f);
          const std::string near = nearest_name(fam, known);
          r.fail(kv.first,
                 "unknown parameter family '" + fam + "'" + (near.empty() ? "" : "; did you mean '" + near + "'?"));
        }
        into[fam] = r.string(kv.second, "unit");
      }
    };
    read(u["revolute"], spec.units);
    read(u["prismatic"], spec.prismatic_units);
  }
}

// robot.yaml's `variants`: each with its description, base, fixed patterns and effects, bases
// resolved.
void read_variants(const Reader& r, const YAML::Node& root, RobotSpec& spec) {
  if (const auto v = root["variants"]) {
    if (!v.IsMap()) r.fail(v, "variants must map variant names to {description, base, fixed, effects}");
    std::vector<RawVariant> raw;
    for (const auto& kv : v) {
      RawVariant rv;
      VariantSpec& vs = rv.spec;
      vs.name = kv.first.Scalar();
      vs.line = kv.first.Mark().line + 1;
      static const std::regex lower_id("^[a-z][a-z0-9_]*$");
      if (!std::regex_match(vs.name, lower_id) || vs.name == "full" || vs.name == "param")
        r.fail(kv.first,
               "variant name '" + vs.name + "' must be a lower-case identifier other than 'full' and 'param'");
      for (const auto& other : raw)
        if (other.spec.name == vs.name) r.fail(kv.first, "duplicate variant name '" + vs.name + "'");
      if (!kv.second.IsMap())
        r.fail(kv.second, "variant " + vs.name + " must be a mapping (description, base, fixed, effects)");
      r.only_keys(kv.second, {"description", "base", "fixed", "effects"}, "variant " + vs.name);
      if (kv.second["description"]) vs.description = r.string(kv.second["description"], "description");
      if (const auto b = kv.second["base"]) {
        vs.base = r.string(b, "base");
        rv.base_node.reset(b);  // reset, not =: assigning a YAML::Node rebinds what it refers to
      }
      const auto f = kv.second["fixed"];
      const auto e = kv.second["effects"];
      if (f && !f.IsMap()) r.fail(f, "variant " + vs.name + ": 'fixed' must map parameter patterns to values");
      if ((!f || f.size() == 0) && vs.base.empty() && !e)
        r.fail(kv.second,
               "variant " + vs.name + " needs 'fixed': a map of parameter patterns to values (or 'base' or 'effects')");
      if (f)
        for (const auto& p : f) vs.fixed.emplace_back(p.first.Scalar(), r.number(p.second, "fixed value"));
      if (e) vs.effects = read_effects(r, e, vs.name);
      raw.push_back(rv);
    }
    resolve_bases(r, raw);
    for (const auto& rv : raw) spec.variants.push_back(rv.spec);
  }
}

// robot.yaml's `urdf`: the description the robot was modelled from (symoroc model).
void read_urdf_section(const Reader& r, const YAML::Node& root, RobotSpec& spec) {
  if (const auto u = root["urdf"]) {
    if (!u.IsMap()) r.fail(u, "urdf must be a mapping (file, base_link, tip_link, ...)");
    r.only_keys(u,
                {"file", "base_link", "tip_link", "frame0_in_base", "tip_in_last_frame", "joints", "links", "locked"},
                "urdf");
    for (const char* k : {"file", "base_link", "tip_link"})
      if (!u[k]) r.fail(u, std::string("urdf needs '") + k + "'");
    spec.urdf.file = r.string(u["file"], "urdf file");
    spec.urdf.base_link = r.string(u["base_link"], "urdf base_link");
    spec.urdf.tip_link = r.string(u["tip_link"], "urdf tip_link");
    if (const auto j = u["joints"]) {
      if (!j.IsSequence()) r.fail(j, "urdf joints must be a list of the URDF's joint names");
      for (const auto& name : j) spec.urdf.joints.push_back(r.string(name, "urdf joint name"));
    }
  }
}

RobotSpec read_robot_spec_checked(const std::string& path) {
  const YAML::Node root = load_yaml_file(path);
  Reader r{path};
  if (!root.IsMap()) throw InputError(path, 1, 1, "robot.yaml must be a mapping of keys");
  r.only_keys(
      root,
      {"name", "description", "constants", "joints", "parameter_units", "identified", "variants", "nominal", "urdf"},
      "robot.yaml");

  RobotSpec spec;
  spec.path = path;
  if (root["description"]) spec.description = r.string(root["description"], "description");

  if (const auto c = root["constants"]) {
    if (!c.IsMap()) r.fail(c, "constants must map names to numbers");
    for (const auto& kv : c) {
      const std::string name = kv.first.Scalar();
      if (!is_identifier(name)) r.fail(kv.first, "'" + name + "' is not a symbol name");
      spec.constants[name] = r.number(kv.second, "constant " + name);
    }
  }

  read_joints(r, root, spec);
  read_units(r, root, spec);
  read_variants(r, root, spec);
  if (const auto nom = root["nominal"]) {
    if (!nom.IsMap()) r.fail(nom, "nominal must map standard parameter names to numbers");
    for (const auto& kv : nom) spec.nominal[kv.first.Scalar()] = r.number(kv.second, "nominal " + kv.first.Scalar());
  }
  read_urdf_section(r, root, spec);
  if (const auto id = root["identified"]) {
    spec.identified = r.string(id, "identified");
    bool known = spec.identified == "full";
    for (const auto& v : spec.variants) known = known || v.name == spec.identified;
    if (!known) r.fail(id, "identified: '" + spec.identified + "' is neither 'full' nor a variant");
  }
  return spec;
}

}  // namespace

RobotSpec read_robot_spec(const std::string& path) {
  // The checks above name each shape they expect; a shape they miss must still be an error at its
  // place in the file, never an escaping yaml-cpp exception (found by fuzz_yaml: a variant given as
  // a scalar).
  try {
    return read_robot_spec_checked(path);
  } catch (const YAML::Exception& e) {
    const int line = e.mark.is_null() ? 1 : e.mark.line + 1, column = e.mark.is_null() ? 1 : e.mark.column + 1;
    throw InputError(path, line, column, "robot.yaml: unexpected shape (" + e.msg + ")");
  }
}

}  // namespace symoro::codegen
