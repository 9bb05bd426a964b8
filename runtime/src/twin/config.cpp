#include "symoro/twin/config.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <set>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "symoro/effect_table.hpp"
#include "symoro/error.hpp"
#include "symoro/io/yaml_keys.hpp"

namespace symoro::twin {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Applies one YAML document to a TwinConfig. The main file must give every section; an
// override file gives only what it changes. Every error names this document's file and line.
class Reader {
 public:
  Reader(std::string file, int joints, bool partial) : file_(std::move(file)), n_(joints), partial_(partial) {}

  [[noreturn]] void fail(const YAML::Node& node, const std::string& message) const {
    throw DataError(file_, node.IsDefined() ? node.Mark().line + 1 : 0, message);
  }

  void check_keys(const YAML::Node& map, const std::string& where, const std::vector<std::string>& allowed) const {
    if (!map.IsMap()) fail(map, where + " must be a map");
    io::check_keys(map, allowed, file_, where);
  }

  // A number, optionally "x deg" (converted to rad).
  double number(const YAML::Node& node, const std::string& what) const {
    if (!node.IsScalar()) fail(node, what + " must be a number");
    std::string s = node.Scalar();
    double scale = 1;
    const auto deg = s.find("deg");
    if (deg != std::string::npos && deg + 3 == s.size()) {
      scale = kPi / 180;
      s = s.substr(0, deg);
    }
    try {
      size_t used = 0;
      const double v = std::stod(s, &used);
      if (s.find_first_not_of(" \t", used) != std::string::npos) throw std::invalid_argument(s);
      if (!std::isfinite(v)) fail(node, what + " must be finite");
      return v * scale;
    } catch (const std::logic_error&) {
      fail(node, what + " must be a number (optionally 'x deg'), not '" + node.Scalar() + "'");
    }
  }

  Eigen::VectorXd vector(const YAML::Node& node, const std::string& what, int size) const {
    if (!node.IsSequence()) fail(node, what + " must be a list of " + std::to_string(size) + " numbers");
    if (static_cast<int>(node.size()) != size)
      fail(node, what + " has " + std::to_string(node.size()) + " entries, expected " + std::to_string(size));
    Eigen::VectorXd v(size);
    for (int i = 0; i < size; ++i) v(i) = number(node[i], what);
    return v;
  }

  Eigen::VectorXd per_joint(const YAML::Node& node, const std::string& what) const { return vector(node, what, n_); }

  Eigen::VectorXd positive_per_joint(const YAML::Node& node, const std::string& what, bool allow_zero) const {
    Eigen::VectorXd v = per_joint(node, what);
    for (int i = 0; i < n_; ++i)
      if (v(i) < 0 || (!allow_zero && v(i) == 0))
        fail(node[i],
             what + " of joint " + std::to_string(i + 1) + " must be " + (allow_zero ? "non-negative" : "positive"));
    return v;
  }

  double positive(const YAML::Node& node, const std::string& what, bool allow_zero = false) const {
    const double v = number(node, what);
    if (v < 0 || (!allow_zero && v == 0)) fail(node, what + " must be " + (allow_zero ? "non-negative" : "positive"));
    return v;
  }

  bool boolean(const YAML::Node& node, const std::string& what) const {
    try {
      return node.as<bool>();
    } catch (const YAML::Exception&) {
      fail(node, what + " must be true or false");
    }
  }

  // A required key of the main file; absent keys of an override are skipped by the caller.
  YAML::Node need(const YAML::Node& map, const std::string& key, const std::string& where) const {
    YAML::Node v = map[key];
    if (!v.IsDefined()) fail(map, where + " lacks '" + key + "'");
    return v;
  }

  template <class F>
  void field(const YAML::Node& map, const std::string& key, const std::string& where, F&& apply) const {
    const YAML::Node v = map[key];
    if (!v.IsDefined()) {
      if (partial_) return;
      fail(map, where + " lacks '" + key + "'");
    }
    apply(v);
  }

  Eigen::Isometry3d pose(const YAML::Node& node, const std::string& what) const {
    check_keys(node, what, {"xyz", "rpy"});
    Eigen::Vector3d xyz = Eigen::Vector3d::Zero(), rpy = Eigen::Vector3d::Zero();
    if (node["xyz"]) xyz = vector(node["xyz"], what + " xyz", 3);
    if (node["rpy"]) rpy = vector(node["rpy"], what + " rpy", 3);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = xyz;
    T.linear() = rotation_rpy(rpy);
    return T;
  }

  static Eigen::Matrix3d rotation_rpy(const Eigen::Vector3d& rpy) {
    // URDF: fixed-axis roll about x, then pitch about y, then yaw about z.
    return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
            Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
        .toRotationMatrix();
  }

  void urdf(const YAML::Node& node, UrdfChain& chain) const {
    check_keys(node, "urdf", {"base_in_urdf", "joints", "inertials"});
    field(node, "base_in_urdf", "urdf", [&](const YAML::Node& v) { chain.base_in_urdf = pose(v, "base_in_urdf"); });
    field(node, "joints", "urdf", [&](const YAML::Node& list) {
      if (!list.IsSequence() || list.size() == 0) fail(list, "urdf joints must be a non-empty list");
      chain.joints.clear();
      std::set<int> seen;
      std::set<std::string> names;
      for (const auto& j : list) {
        check_keys(j, "a urdf joint", {"name", "type", "joint", "xyz", "rpy", "axis"});
        UrdfJoint u;
        u.name = need(j, "name", "a urdf joint").as<std::string>();
        if (!names.insert(u.name).second) fail(j, "duplicate urdf joint '" + u.name + "'");
        const std::string type = j["type"] ? j["type"].as<std::string>() : "revolute";
        if (type != "fixed" && type != "revolute") fail(j["type"], "urdf joint type must be fixed or revolute");
        u.fixed = type == "fixed";
        if (j["xyz"]) u.xyz = vector(j["xyz"], "xyz of " + u.name, 3);
        if (j["rpy"]) u.rpy = vector(j["rpy"], "rpy of " + u.name, 3);
        if (!u.fixed) {
          const double jn = number(need(j, "joint", "urdf joint " + u.name), "joint of " + u.name);
          u.model_joint = static_cast<int>(jn);
          if (u.model_joint != jn || u.model_joint < 1 || u.model_joint > n_)
            fail(j["joint"], "joint of " + u.name + " must be a model joint 1.." + std::to_string(n_));
          if (!seen.insert(u.model_joint).second)
            fail(j["joint"], "model joint " + std::to_string(u.model_joint) + " appears twice");
          u.axis = vector(need(j, "axis", "urdf joint " + u.name), "axis of " + u.name, 3);
          if (u.axis.norm() < 1e-9) fail(j["axis"], "axis of " + u.name + " is zero");
          u.axis.normalize();
        }
        chain.joints.push_back(u);
      }
    });
    field(node, "inertials", "urdf", [&](const YAML::Node& list) {
      if (!list.IsSequence()) fail(list, "urdf inertials must be a list");
      chain.inertials.clear();
      for (const auto& b : list) {
        check_keys(b, "an inertial", {"name", "on", "origin", "mass", "com", "rpy", "inertia"});
        UrdfInertial u;
        u.name = need(b, "name", "an inertial").as<std::string>();
        u.on = need(b, "on", "inertial " + u.name).as<std::string>();
        bool found = false;
        for (const auto& j : chain.joints) found = found || j.name == u.on;
        if (!found) fail(b["on"], "inertial " + u.name + " is on '" + u.on + "', which is not a urdf joint");
        if (b["origin"]) u.origin = vector(b["origin"], "origin of " + u.name, 3);
        u.mass = positive(need(b, "mass", "inertial " + u.name), "mass of " + u.name);
        u.com = vector(need(b, "com", "inertial " + u.name), "com of " + u.name, 3);
        if (b["rpy"]) u.rpy = vector(b["rpy"], "rpy of " + u.name, 3);
        const Eigen::VectorXd i = vector(need(b, "inertia", "inertial " + u.name), "inertia of " + u.name, 6);
        u.inertia << i(0), i(1), i(2), i(1), i(3), i(4), i(2), i(4), i(5);
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(u.inertia);
        const Eigen::Vector3d l = eig.eigenvalues();
        if (l(0) < 0 || l(0) + l(1) < l(2) * (1 - 1e-9))
          fail(b["inertia"],
               "inertia of " + u.name +
                   " is not physical (principal moments must be non-negative and satisfy the triangle inequality)");
        chain.inertials.push_back(u);
      }
    });
  }

  Servo servo(const YAML::Node& node) const {
    check_keys(node, "a servo", {"model", "torque_constant", "current_unit", "current_limit", "encoder_counts"});
    Servo s;
    s.model = need(node, "model", "a servo").as<std::string>();
    s.torque_constant = positive(need(node, "torque_constant", "servo " + s.model), "torque_constant");
    s.current_unit = positive(need(node, "current_unit", "servo " + s.model), "current_unit");
    s.current_limit = positive(need(node, "current_limit", "servo " + s.model), "current_limit");
    const double counts = positive(need(node, "encoder_counts", "servo " + s.model), "encoder_counts");
    s.encoder_counts = static_cast<int>(counts);
    if (s.encoder_counts != counts || s.encoder_counts < 2)
      fail(node["encoder_counts"], "encoder_counts must be an integer >= 2");
    return s;
  }

  void controller(const YAML::Node& node, ControllerConfig& c) const {
    check_keys(
        node, "controller",
        {"period", "pseudo_derivative_time", "communication_delay", "realization", "bandwidth", "damping_ratio"});
    field(node, "period", "controller", [&](const YAML::Node& v) { c.period = positive(v, "period"); });
    field(node, "pseudo_derivative_time", "controller",
          [&](const YAML::Node& v) { c.pseudo_derivative_time = positive(v, "pseudo_derivative_time"); });
    field(node, "communication_delay", "controller",
          [&](const YAML::Node& v) { c.communication_delay = positive(v, "communication_delay", true); });
    field(node, "realization", "controller", [&](const YAML::Node& r) {
      check_keys(r, "realization", {"inertia", "damping"});
      field(r, "inertia", "realization",
            [&](const YAML::Node& v) { c.realization_inertia = positive_per_joint(v, "realization inertia", false); });
      field(r, "damping", "realization",
            [&](const YAML::Node& v) { c.realization_damping = positive_per_joint(v, "realization damping", true); });
    });
    field(node, "bandwidth", "controller",
          [&](const YAML::Node& v) { c.bandwidth = positive_per_joint(v, "bandwidth", false); });
    field(node, "damping_ratio", "controller",
          [&](const YAML::Node& v) { c.damping_ratio = positive_per_joint(v, "damping_ratio", false); });
  }

  void effects(const YAML::Node& node, Effects& e) const {
    check_keys(node, "effects", Effects::names());
    auto section = [&](const char* name, const std::vector<std::string>& keys, bool& enabled, auto&& body) {
      const YAML::Node s = node[name];
      if (!s.IsDefined()) {
        if (partial_ || std::string(name) == "contact") return;  // a contact is an experiment's, not the arm's
        fail(node, std::string("effects lacks '") + name + "'");
      }
      std::vector<std::string> allowed{"enabled"};
      allowed.insert(allowed.end(), keys.begin(), keys.end());
      check_keys(s, std::string("effect ") + name, allowed);
      field(s, "enabled", name, [&](const YAML::Node& v) { enabled = boolean(v, std::string(name) + " enabled"); });
      body(s);
    };
    section("coulomb", {"torque", "smoothing_velocity"}, e.coulomb, [&](const YAML::Node& s) {
      field(s, "torque", "coulomb",
            [&](const YAML::Node& v) { e.coulomb_torque = positive_per_joint(v, "coulomb torque", true); });
      field(s, "smoothing_velocity", "coulomb",
            [&](const YAML::Node& v) { e.coulomb_smoothing_velocity = positive(v, "smoothing_velocity"); });
    });
    section("stribeck", {"torque", "velocity"}, e.stribeck, [&](const YAML::Node& s) {
      field(s, "torque", "stribeck",
            [&](const YAML::Node& v) { e.stribeck_torque = positive_per_joint(v, "stribeck torque", true); });
      field(s, "velocity", "stribeck",
            [&](const YAML::Node& v) { e.stribeck_velocity = positive(v, "stribeck velocity"); });
    });
    section("torque_offset", {"torque"}, e.torque_offset, [&](const YAML::Node& s) {
      field(s, "torque", "torque_offset",
            [&](const YAML::Node& v) { e.offset_torque = per_joint(v, "offset torque"); });
    });
    section("backlash", {"width", "frequency", "damping_ratio"}, e.backlash, [&](const YAML::Node& s) {
      field(s, "width", "backlash",
            [&](const YAML::Node& v) { e.backlash_width = positive_per_joint(v, "backlash width", true); });
      field(s, "frequency", "backlash",
            [&](const YAML::Node& v) { e.backlash_frequency = positive(v, "backlash frequency"); });
      field(s, "damping_ratio", "backlash",
            [&](const YAML::Node& v) { e.backlash_damping_ratio = positive(v, "backlash damping_ratio", true); });
    });
    section("payload", {"mass", "com", "inertia"}, e.payload, [&](const YAML::Node& s) {
      field(s, "mass", "payload", [&](const YAML::Node& v) { e.payload_mass = positive(v, "payload mass", true); });
      field(s, "com", "payload", [&](const YAML::Node& v) { e.payload_com = vector(v, "payload com", 3); });
      if (s["inertia"].IsDefined()) {                                          // optional: without it, a point mass
        const Eigen::VectorXd i = vector(s["inertia"], "payload inertia", 6);  // ixx ixy ixz iyy iyz izz
        e.payload_inertia << i(0), i(1), i(2), i(1), i(3), i(4), i(2), i(4), i(5);
      }
    });
    section("torque_constant_error", {"scale"}, e.torque_constant_error, [&](const YAML::Node& s) {
      field(s, "scale", "torque_constant_error", [&](const YAML::Node& v) {
        e.torque_constant_scale = positive_per_joint(v, "torque constant scale", false);
      });
    });
    section("actuation_delay", {"delay"}, e.actuation_delay, [&](const YAML::Node& s) {
      field(s, "delay", "actuation_delay",
            [&](const YAML::Node& v) { e.actuation_delay_time = positive(v, "actuation delay", true); });
    });
    section("sensor_noise", {"encoder", "current"}, e.sensor_noise, [&](const YAML::Node& s) {
      field(s, "encoder", "sensor_noise",
            [&](const YAML::Node& v) { e.encoder_noise = positive(v, "encoder noise", true); });
      field(s, "current", "sensor_noise",
            [&](const YAML::Node& v) { e.current_noise = positive(v, "current noise", true); });
    });
    section("timestamp_jitter", {"std", "max"}, e.timestamp_jitter, [&](const YAML::Node& s) {
      field(s, "std", "timestamp_jitter", [&](const YAML::Node& v) { e.jitter_std = positive(v, "jitter std", true); });
      field(s, "max", "timestamp_jitter", [&](const YAML::Node& v) { e.jitter_max = positive(v, "jitter max", true); });
    });
    section("dropped_samples", {"probability", "max_burst"}, e.dropped_samples, [&](const YAML::Node& s) {
      field(s, "probability", "dropped_samples", [&](const YAML::Node& v) {
        e.drop_probability = positive(v, "drop probability", true);
        if (e.drop_probability >= 0.5) fail(v, "drop probability must be below 0.5");
      });
      field(s, "max_burst", "dropped_samples", [&](const YAML::Node& v) {
        const double b = positive(v, "max_burst");
        e.drop_max_burst = static_cast<int>(b);
        if (e.drop_max_burst != b) fail(v, "max_burst must be an integer");
      });
    });
    section("contact", {"joint", "start", "duration", "torque"}, e.contact, [&](const YAML::Node& s) {
      field(s, "joint", "contact", [&](const YAML::Node& v) {
        const double j = positive(v, "contact joint");
        e.contact_joint = static_cast<int>(j);
        if (e.contact_joint != j || e.contact_joint > n_)
          fail(v, fmt::format("contact joint must be a joint number from 1 to {}", n_));
      });
      field(s, "start", "contact", [&](const YAML::Node& v) { e.contact_start = number(v, "contact start"); });
      field(s, "duration", "contact",
            [&](const YAML::Node& v) { e.contact_duration = positive(v, "contact duration", true); });
      field(s, "torque", "contact", [&](const YAML::Node& v) { e.contact_torque = number(v, "contact torque"); });
    });
  }

  void apply(const YAML::Node& root, TwinConfig& c) const {
    check_keys(root, "the twin configuration",
               {"format", "urdf", "drives", "servos", "controller", "integration", "effects"});
    field(root, "format", "the twin configuration", [&](const YAML::Node& v) {
      if (v.as<std::string>() != "symoro-twin 1") fail(v, "format must be 'symoro-twin 1'");
    });
    field(root, "urdf", "the twin configuration", [&](const YAML::Node& v) { urdf(v, c.chain); });
    field(root, "drives", "the twin configuration", [&](const YAML::Node& d) {
      check_keys(d, "drives", {"rotor_inertia", "viscous"});
      field(d, "rotor_inertia", "drives",
            [&](const YAML::Node& v) { c.rotor_inertia = positive_per_joint(v, "rotor_inertia", true); });
      field(d, "viscous", "drives", [&](const YAML::Node& v) { c.viscous = positive_per_joint(v, "viscous", true); });
    });
    field(root, "servos", "the twin configuration", [&](const YAML::Node& list) {
      if (!list.IsSequence() || static_cast<int>(list.size()) != n_)
        fail(list, "servos must list one servo per joint (" + std::to_string(n_) + ")");
      c.servos.clear();
      for (const auto& s : list) c.servos.push_back(servo(s));
    });
    if (root["controller"].IsDefined()) controller(root["controller"], c.controller);  // else controller.yaml
    field(root, "integration", "the twin configuration", [&](const YAML::Node& v) {
      check_keys(v, "integration", {"max_step"});
      field(v, "max_step", "integration", [&](const YAML::Node& s) { c.max_step = positive(s, "max_step"); });
    });
    field(root, "effects", "the twin configuration", [&](const YAML::Node& v) { effects(v, c.effects); });
  }

 private:
  std::string file_;
  int n_;
  bool partial_;
};

YAML::Node load(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) throw DataError(path.string(), 0, "no such file");
  YAML::Node root = io::load_yaml_file(path);
  // A scalar or a list: the first lookup threw yaml-cpp's BadSubscript past every handler (fuzz_yaml).
  if (!root.IsMap() && !root.IsNull())
    throw DataError(path.string(), root.Mark().is_null() ? 1 : root.Mark().line + 1,
                    "expected a YAML map of sections (twin.yaml)");
  return root;
}

}  // namespace

// The twin's effects are the effect table's rows with a twin name, in the table's order; the
// flags of set() and enabled() follow that order.
const std::vector<std::string>& Effects::names() {
  static const std::vector<std::string> v = [] {
    std::vector<std::string> out;
    for (const EffectRow& row : kEffectTable)
      if (!row.twin.empty()) out.emplace_back(row.twin);
    return out;
  }();
  return v;
}

void Effects::set(const std::string& name, bool on) {
  bool* flags[] = {
      &coulomb,         &stribeck,     &torque_offset,    &backlash,        &payload, &torque_constant_error,
      &actuation_delay, &sensor_noise, &timestamp_jitter, &dropped_samples, &contact};
  const auto& n = names();
  if (n.size() != std::size(flags))
    throw std::logic_error("the twin's effect flags and the effect table's twin names differ");
  for (size_t i = 0; i < n.size(); ++i)
    if (n[i] == name) {
      *flags[i] = on;
      return;
    }
  std::string all;
  for (const auto& s : n) all += (all.empty() ? "" : ", ") + s;
  throw std::invalid_argument("unknown twin effect '" + name + "' (known: " + all + ")");
}

double Effects::contact_at(double t) const {
  const double ramp = 0.002, in = t - contact_start, left = contact_start + contact_duration - t;
  if (!contact || in <= 0 || left <= 0) return 0;
  return contact_torque * std::min({1.0, in / ramp, left / ramp});
}

void Effects::disable_all() {
  for (const auto& n : names()) set(n, false);
}

std::vector<std::string> Effects::enabled() const {
  const bool flags[] = {
      coulomb,         stribeck,     torque_offset,    backlash,        payload, torque_constant_error,
      actuation_delay, sensor_noise, timestamp_jitter, dropped_samples, contact};
  std::vector<std::string> out;
  for (size_t i = 0; i < std::size(flags) && i < names().size(); ++i)
    if (flags[i]) out.push_back(names()[i]);
  return out;
}

// FNV-1a over the files' bytes: enough to tell two configurations apart in a log's notes.
std::string fingerprint(const std::vector<std::filesystem::path>& files) {
  std::uint64_t h = 1469598103934665603ull;
  for (const auto& f : files) {
    std::ifstream in(f, std::ios::binary);
    for (char ch; in.get(ch);) h = (h ^ static_cast<unsigned char>(ch)) * 1099511628211ull;
    h = (h ^ 0xff) * 1099511628211ull;
  }
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}

TwinConfig read_twin_config(const std::filesystem::path& path, int joints, const std::filesystem::path& override_path) {
  TwinConfig c;
  c.path = path.string();
  const YAML::Node root = load(path);
  std::vector<std::filesystem::path> files{path};
  if (!root["controller"].IsDefined()) {
    const auto description = path.parent_path() / control::controller_file_name();
    if (!std::filesystem::exists(description))
      throw DataError(path.string(), 0,
                      fmt::format("no 'controller' section and no controller description ({})", description.string()));
    c.controller = control::read_controller_description(description, joints);
    files.push_back(description);
  }
  Reader(path.string(), joints, false).apply(root, c);
  if (!override_path.empty()) {
    Reader(override_path.string(), joints, true).apply(load(override_path), c);
    files.push_back(override_path);
  }
  c.fingerprint = fingerprint(files);
  const double T = c.controller.period;
  if (c.controller.communication_delay >= T)
    throw DataError(path.string(), 0, "controller communication_delay must be shorter than the period");
  if (c.max_step > T) throw DataError(path.string(), 0, "integration max_step must not exceed the controller period");
  return c;
}

}  // namespace symoro::twin
