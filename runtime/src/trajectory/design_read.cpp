// Reading and validating a trajectory design file. Every problem is reported with the file and
// the line of the offending YAML node; nothing is defaulted silently except the keys the format
// documents as optional (patterns, wrist_variant, an item's posture, speed, class and signs).
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <sstream>

#include "design_data.hpp"
#include "symoro/detail/numbers.hpp"
#include "symoro/error.hpp"
#include "symoro/io/yaml_keys.hpp"

namespace symoro::trajectory {

int Design::levels() const {
  return speed_factors.empty() ? 0 : static_cast<int>(speed_factors.begin()->second.size());
}

namespace {

using symoro::detail::kDeg;

std::string degrees(double rad) {
  std::ostringstream out;
  out.precision(6);
  out << rad / kDeg;
  return out.str();
}

class Reader {
 public:
  Reader(std::string file, int joints) : file_(std::move(file)), n_(joints) {}

  [[noreturn]] void fail(const YAML::Node& node, const std::string& message) const {
    throw DataError(file_, node.IsDefined() ? static_cast<int>(node.Mark().line) + 1 : 0, message);
  }

  // A mapping whose keys are all in `allowed` (each at most once) and include `required`.
  void keys(const YAML::Node& map, const std::string& where, const std::vector<std::string>& allowed,
            const std::set<std::string>& required) const {
    if (!map.IsMap()) fail(map, where + " must be a mapping");
    io::check_keys(map, allowed, file_, where);
    for (const auto& key : required)
      if (!map[key]) fail(map, where + " lacks the key '" + key + "'");
  }

  // The mapping's entries in file order, keys checked for duplicates.
  std::vector<std::pair<std::string, YAML::Node>> entries(const YAML::Node& map, const std::string& where) const {
    if (!map.IsMap()) fail(map, where + " must be a mapping");
    std::vector<std::pair<std::string, YAML::Node>> out;
    std::set<std::string> seen;
    for (const auto& entry : map) {
      const std::string key = scalar(entry.first, "a key of " + where);
      if (!seen.insert(key).second) fail(entry.first, "duplicate key '" + key + "' in " + where);
      out.emplace_back(key, entry.second);
    }
    return out;
  }

  std::string scalar(const YAML::Node& node, const std::string& what) const {
    if (!node.IsScalar()) fail(node, what + " must be a single value");
    return node.Scalar();
  }

  double number(const YAML::Node& node, const std::string& what) const {
    const std::string text = scalar(node, what);
    double value = 0;
    try {
      value = node.as<double>();
    } catch (const YAML::Exception&) {
      fail(node, what + " must be a number, not '" + text + "'");
    }
    if (!std::isfinite(value)) fail(node, what + " must be finite, not '" + text + "'");
    return value;
  }

  double at_least(const YAML::Node& node, const std::string& what, double lowest) const {
    const double value = number(node, what);
    if (value < lowest) fail(node, what + " must be at least " + format(lowest) + ", not " + format(value));
    return value;
  }

  double positive(const YAML::Node& node, const std::string& what) const {
    const double value = number(node, what);
    if (!(value > 0)) fail(node, what + " must be positive, not " + format(value));
    return value;
  }

  int integer(const YAML::Node& node, const std::string& what, int lowest, int highest) const {
    const double value = number(node, what);
    if (value != std::floor(value) || value < lowest || value > highest)
      fail(node, what + " must be an integer in " + std::to_string(lowest) + ".." + std::to_string(highest) + ", not " +
                     scalar(node, what));
    return static_cast<int>(value);
  }

  // The node itself (by value: yaml-cpp nodes are handles, and callers pass temporaries).
  YAML::Node sequence(const YAML::Node& node, const std::string& what, std::size_t size = 0) const {
    if (!node.IsSequence()) fail(node, what + " must be a list");
    if (size > 0 && node.size() != size)
      fail(node, what + " must have " + std::to_string(size) + " entries, not " + std::to_string(node.size()));
    if (node.size() == 0) fail(node, what + " must not be empty");
    return node;
  }

  // n numbers, one per joint.
  Eigen::VectorXd per_joint(const YAML::Node& node, const std::string& what, double scale = 1.0) const {
    sequence(node, what + " (one value per joint)", static_cast<std::size_t>(n_));
    Eigen::VectorXd out(n_);
    for (int j = 0; j < n_; ++j) out[j] = number(node[j], what + " entry " + std::to_string(j + 1)) * scale;
    return out;
  }

  static std::string format(double value) {
    std::ostringstream out;
    out << value;
    return out.str();
  }

 private:
  std::string file_;
  int n_;
};

// Reads the whole design; `d` holds what has been read so far.
class DesignReader {
 public:
  DesignReader(Design& d, const Reader& r) : d_(d), r_(r), n_(static_cast<int>(d.joints.size())) {}

  void read(const YAML::Node& root) {
    r_.keys(root, "the design",
            {"robot", "joints", "limits", "speed_factors", "joint_class", "timing", "postures", "wrist_variant",
             "primitives", "patterns", "trajectories"},
            {"robot", "joints", "limits", "speed_factors", "joint_class", "timing", "postures", "primitives",
             "trajectories"});
    d_.robot = r_.scalar(root["robot"], "robot");
    joints(root["joints"]);
    limits(root["limits"]);
    speed_factors(root["speed_factors"]);
    joint_class(root["joint_class"]);
    timing(root["timing"]);
    postures(root["postures"]);
    if (root["wrist_variant"]) wrist_variant(root["wrist_variant"]);
    primitives(root["primitives"]);
    if (root["patterns"]) patterns(root["patterns"]);
    trajectories(root["trajectories"]);
  }

 private:
  void joints(const YAML::Node& node) {
    r_.sequence(node, "joints (the robot's joint names, in order)");
    if (static_cast<int>(node.size()) != n_)
      r_.fail(node, "joints lists " + std::to_string(node.size()) + " joints; the robot has " + std::to_string(n_));
    for (int j = 0; j < n_; ++j) {
      const std::string name = r_.scalar(node[j], "joint name");
      if (name != d_.joint_names[j])
        r_.fail(node[j],
                "joint " + std::to_string(j + 1) + " is '" + d_.joint_names[j] + "' in the robot, not '" + name + "'");
    }
  }

  void limits(const YAML::Node& node) {
    r_.keys(node, "limits", {"position_margin", "velocity", "acceleration"},
            {"position_margin", "velocity", "acceleration"});
    d_.position_margin = r_.at_least(node["position_margin"], "limits.position_margin", 0) * kDeg;
    d_.velocity = r_.per_joint(node["velocity"], "limits.velocity");
    d_.acceleration = r_.per_joint(node["acceleration"], "limits.acceleration");
    for (int j = 0; j < n_; ++j) {
      if (!(d_.velocity[j] > 0)) r_.fail(node["velocity"][j], "limits.velocity must be positive");
      if (!(d_.acceleration[j] > 0)) r_.fail(node["acceleration"][j], "limits.acceleration must be positive");
    }
  }

  void speed_factors(const YAML::Node& node) {
    std::size_t levels = 0;
    for (const auto& [name, list] : r_.entries(node, "speed_factors")) {
      r_.sequence(list, "speed_factors." + name);
      if (levels == 0) levels = list.size();
      if (list.size() != levels)
        r_.fail(list, "speed_factors." + name + " has " + std::to_string(list.size()) +
                          " levels; the first class has " + std::to_string(levels));
      std::vector<double> factors;
      for (const auto& f : list) {
        const double factor = r_.positive(f, "a speed factor");
        if (factor > 1) r_.fail(f, "a speed factor must not exceed 1, not " + Reader::format(factor));
        factors.push_back(factor);
      }
      d_.speed_factors[name] = factors;
    }
    if (d_.speed_factors.empty()) r_.fail(node, "speed_factors must name at least one class");
  }

  std::string speed_class(const YAML::Node& node) const {
    const std::string name = r_.scalar(node, "a speed class");
    if (!d_.speed_factors.count(name)) r_.fail(node, "unknown speed class '" + name + "' (not in speed_factors)");
    return name;
  }

  void joint_class(const YAML::Node& node) {
    r_.sequence(node, "joint_class (one class per joint)", static_cast<std::size_t>(n_));
    for (int j = 0; j < n_; ++j) d_.joint_class.push_back(speed_class(node[j]));
  }

  void timing(const YAML::Node& node) {
    r_.keys(node, "timing", {"start_hold", "end_hold", "waypoint_dwell", "primitive_dwell"},
            {"start_hold", "end_hold", "waypoint_dwell", "primitive_dwell"});
    // The closed-loop twin and the robot need at least 1 s at rest at both ends.
    d_.start_hold = r_.at_least(node["start_hold"], "timing.start_hold", 1.0);
    d_.end_hold = r_.at_least(node["end_hold"], "timing.end_hold", 1.0);
    d_.waypoint_dwell = r_.at_least(node["waypoint_dwell"], "timing.waypoint_dwell", 0.0);
    d_.primitive_dwell = r_.at_least(node["primitive_dwell"], "timing.primitive_dwell", 0.0);
  }

  // A joint-space point in deg, inside the position limits less the margin.
  Eigen::VectorXd point(const YAML::Node& node, const std::string& what) const {
    const Eigen::VectorXd q = r_.per_joint(node, what, kDeg);
    for (int j = 0; j < n_; ++j) {
      const JointInfo& joint = d_.joints[j];
      const double low = joint.lower + d_.position_margin, high = joint.upper - d_.position_margin;
      if (q[j] < low || q[j] > high)
        r_.fail(node[j], what + ": joint " + std::to_string(j + 1) + " (" + d_.joint_names[j] + ") at " +
                             degrees(q[j]) + " deg is outside [" + degrees(low) + ", " + degrees(high) +
                             "] deg (its limits less the position margin)");
    }
    return q;
  }

  void postures(const YAML::Node& node) {
    for (const auto& [name, value] : r_.entries(node, "postures")) {
      if (name.empty() || name.back() == '\'')
        r_.fail(value, "posture name '" + name + "' may not end in ' (reserved for the wrist variants)");
      d_.postures[name] = point(value, "posture " + name);
      d_.base_posture[name] = name;
    }
    if (d_.postures.empty()) r_.fail(node, "postures must define at least one posture");
  }

  void wrist_variant(const YAML::Node& node) {
    r_.keys(node, "wrist_variant", {"joint", "offset"}, {"joint", "offset"});
    const int joint = r_.integer(node["joint"], "wrist_variant.joint", 1, n_) - 1;
    const double offset = r_.number(node["offset"], "wrist_variant.offset") * kDeg;
    const auto bases = d_.postures;
    for (const auto& [name, q] : bases) {
      Eigen::VectorXd variant = q;
      variant[joint] += offset;
      const JointInfo& info = d_.joints[joint];
      if (variant[joint] < info.lower + d_.position_margin || variant[joint] > info.upper - d_.position_margin)
        r_.fail(node["offset"], "the wrist variant " + name + "' puts joint " + std::to_string(joint + 1) + " at " +
                                    degrees(variant[joint]) + " deg, outside its limits less the position margin");
      d_.postures[name + "'"] = variant;
      d_.base_posture[name + "'"] = name;
    }
  }

  void primitives(const YAML::Node& node) {
    for (const auto& [name, value] : r_.entries(node, "primitives")) {
      if (!d_.postures.count(name) || d_.base_posture.at(name) != name)
        r_.fail(value, "primitives: '" + name + "' is not a posture of `postures`");
      r_.keys(value, "primitives." + name, {"amplitude", "center"}, {"amplitude"});
      PrimitiveParameters p;
      p.amplitude = r_.per_joint(value["amplitude"], "primitives." + name + ".amplitude", kDeg);
      for (int j = 0; j < n_; ++j)
        if (p.amplitude[j] < 0) r_.fail(value["amplitude"][j], "an amplitude must not be negative");
      p.center = value["center"] ? r_.per_joint(value["center"], "primitives." + name + ".center", kDeg)
                                 : Eigen::VectorXd::Zero(n_);
      d_.primitive_parameters[name] = p;
    }
  }

  // A 1-based joint number in the file, 0-based in the design.
  int joint_number(const YAML::Node& node) const { return r_.integer(node, "a joint number", 1, n_) - 1; }

  // The primitives of `single:` or `pair:` (+ `signs:`) in `node`, a mapping already key-checked.
  std::vector<PrimitiveSpec> primitive_list(const YAML::Node& node) const {
    std::vector<PrimitiveSpec> out;
    if (node["single"]) {
      if (node["signs"]) r_.fail(node["signs"], "signs apply to pair primitives only");
      for (const auto& j : r_.sequence(node["single"], "single (a list of joints)"))
        out.push_back({{joint_number(j)}, {1}});
      return out;
    }
    std::vector<int> signs{1, 1};
    if (node["signs"]) {
      r_.sequence(node["signs"], "signs", 2);
      for (int k = 0; k < 2; ++k) {
        signs[k] = r_.integer(node["signs"][k], "a sign", -1, 1);
        if (signs[k] == 0) r_.fail(node["signs"][k], "a sign must be 1 or -1");
      }
    }
    const YAML::Node pairs = r_.sequence(node["pair"], "pair ([j, j+1] or a list of them)");
    const bool one_pair = !pairs[0].IsSequence();
    auto read_pair = [&](const YAML::Node& pair) {
      r_.sequence(pair, "a pair [j, j+1]", 2);
      const int first = joint_number(pair[0]), second = joint_number(pair[1]);
      if (second != first + 1)
        r_.fail(pair, "a pair primitive needs adjacent joints [j, j+1], not [" + std::to_string(first + 1) + ", " +
                          std::to_string(second + 1) + "]");
      out.push_back({{first, second}, signs});
    };
    if (one_pair)
      read_pair(pairs);
    else
      for (const auto& pair : pairs) read_pair(pair);
    return out;
  }

  static std::string describe(const std::vector<PrimitiveSpec>& primitives) {
    std::string out;
    for (const auto& p : primitives) {
      out += out.empty() ? "P" : " P";
      out += std::to_string(p.joints[0] + 1);
      if (p.joints.size() == 2)
        out += "," + std::to_string(p.joints[1] + 1) + (p.signs[1] == p.signs[0] ? "(in)" : "(opp)");
    }
    return out;
  }

  void patterns(const YAML::Node& node) {
    for (const auto& [name, list] : r_.entries(node, "patterns")) {
      std::vector<PrimitiveSpec> primitives;
      for (const auto& item : r_.sequence(list, "pattern " + name)) {
        r_.keys(item, "an item of pattern " + name, {"single", "pair", "signs"}, {});
        if (!!item["single"] == !!item["pair"]) r_.fail(item, "a pattern item needs exactly one of single and pair");
        for (auto& p : primitive_list(item)) primitives.push_back(std::move(p));
      }
      patterns_[name] = std::move(primitives);
    }
  }

  std::string posture_name(const YAML::Node& node) const {
    const std::string name = r_.scalar(node, "a posture");
    if (!d_.postures.count(name)) {
      std::string known;
      for (const auto& [p, q] : d_.postures) known += (known.empty() ? "" : ", ") + p;
      r_.fail(node, "unknown posture '" + name + "' (known: " + known + ")");
    }
    return name;
  }

  ItemSpec item(const YAML::Node& node, const TrajectorySpec& t) const {
    r_.keys(node, "an item of " + t.name,
            {"pattern", "single", "pair", "signs", "waypoints", "fourier", "posture", "speed", "class"}, {});
    const int kinds = !!node["pattern"] + !!node["single"] + !!node["pair"] + !!node["waypoints"] + !!node["fourier"];
    if (kinds != 1)
      r_.fail(node, "an item of " + t.name + " needs exactly one of pattern, single, pair, waypoints and fourier");
    ItemSpec item;
    item.line = static_cast<int>(node.Mark().line) + 1;
    item.posture = node["posture"] ? posture_name(node["posture"]) : t.posture;
    item.speed = node["speed"] ? r_.integer(node["speed"], "speed (a level)", 1, d_.levels()) : t.speed;
    if (node["class"]) item.speed_class = speed_class(node["class"]);
    if (node["fourier"]) {
      for (const char* key : {"signs", "posture", "speed", "class"})
        if (node[key])
          r_.fail(node[key],
                  std::string("a fourier item starts where the arm is and keeps its own timing: it takes no ") + key);
      item.kind = ItemSpec::Kind::Fourier;
      fourier(node["fourier"], t.name, item);
    } else if (node["waypoints"]) {
      if (node["signs"]) r_.fail(node["signs"], "signs apply to pair primitives only");
      if (node["posture"]) r_.fail(node["posture"], "waypoints are absolute: they take no posture");
      item.kind = ItemSpec::Kind::Waypoints;
      int k = 0;
      for (const auto& w : r_.sequence(node["waypoints"], "waypoints"))
        item.waypoints.push_back(point(w, t.name + " waypoint " + std::to_string(++k)));
      item.summary = std::to_string(item.waypoints.size()) + " waypoints";
    } else {
      if (node["pattern"]) {
        if (node["signs"]) r_.fail(node["signs"], "signs apply to pair primitives only");
        const std::string name = r_.scalar(node["pattern"], "a pattern name");
        const auto found = patterns_.find(name);
        if (found == patterns_.end()) r_.fail(node["pattern"], "unknown pattern '" + name + "'");
        item.primitives = found->second;
        item.summary = name + " (" + describe(item.primitives) + ")";
      } else {
        item.primitives = primitive_list(node);
        item.summary = describe(item.primitives);
      }
      if (!d_.primitive_parameters.count(d_.base_posture.at(item.posture)))
        r_.fail(node, "posture " + d_.base_posture.at(item.posture) + " has no entry in primitives (amplitudes)");
      item.summary += " at " + item.posture;
    }
    if (item.kind != ItemSpec::Kind::Fourier) item.summary += ", speed " + std::to_string(item.speed);
    return item;
  }

  // fourier: {period: T s, periods: P, a: [[a_j1 .. a_jL] per joint], b: [...]} in rad/s, at
  // rest at t = 0 (sum_l a_jl = 0, sum_l l b_jl = 0; trajectory/fourier.hpp).
  void fourier(const YAML::Node& node, const std::string& name, ItemSpec& item) const {
    r_.keys(node, "fourier of " + name, {"period", "periods", "a", "b"}, {"period", "a", "b"});
    auto series = std::make_shared<FourierTrajectory>();
    series->name = name;
    series->w = 2 * 3.14159265358979323846 / r_.positive(node["period"], "fourier.period");
    item.periods = node["periods"] ? r_.integer(node["periods"], "fourier.periods", 1, 1000) : 1;
    auto matrix = [&](const YAML::Node& m, const char* key, Eigen::MatrixXd& out) {
      r_.sequence(m, std::string("fourier.") + key + " (one list of harmonics per joint)",
                  static_cast<std::size_t>(n_));
      const std::size_t L = r_.sequence(m[0], std::string("fourier.") + key + " of joint 1").size();
      if (L < 2) r_.fail(m[0], "fourier needs at least 2 harmonics");
      out.resize(n_, static_cast<Eigen::Index>(L));
      for (int j = 0; j < n_; ++j) {
        const YAML::Node row =
            r_.sequence(m[j], std::string("fourier.") + key + " of joint " + std::to_string(j + 1), L);
        for (std::size_t l = 0; l < L; ++l)
          out(j, static_cast<Eigen::Index>(l)) = r_.number(row[l], std::string("fourier.") + key);
      }
    };
    matrix(node["a"], "a", series->a);
    matrix(node["b"], "b", series->b);
    if (series->a.cols() != series->b.cols())
      r_.fail(node["b"], "fourier.a and fourier.b need the same number of harmonics");
    for (int j = 0; j < n_; ++j) {
      double sa = 0, sb = 0, scale = 1e-300;
      for (Eigen::Index l = 0; l < series->a.cols(); ++l) {
        sa += series->a(j, l);
        sb += (l + 1.0) * series->b(j, l);
        scale = std::max({scale, std::abs(series->a(j, l)), (l + 1.0) * std::abs(series->b(j, l))});
      }
      if (std::abs(sa) > 1e-9 * scale || std::abs(sb) > 1e-9 * scale)
        r_.fail(node, "fourier of " + name + ": joint " + std::to_string(j + 1) + " (" + d_.joint_names[j] +
                          ") is not at rest at t = 0 (sum a = " + Reader::format(sa) +
                          ", sum l b = " + Reader::format(sb) + ", both must be 0)");
    }
    item.fourier = std::move(series);
    item.summary = "fourier " + std::to_string(item.fourier->harmonics()) + " harmonics, " +
                   Reader::format(item.fourier->period()) + " s x " + std::to_string(item.periods);
  }

  void trajectories(const YAML::Node& node) {
    std::set<std::string> names;
    for (const auto& entry : r_.sequence(node, "trajectories")) {
      r_.keys(entry, "a trajectory", {"name", "description", "posture", "speed", "sequence"},
              {"name", "posture", "speed", "sequence"});
      TrajectorySpec t;
      t.line = static_cast<int>(entry.Mark().line) + 1;
      t.name = r_.scalar(entry["name"], "a trajectory name");
      // The family is the name's letters (PA01 -> PA, V03 -> V).
      const auto digits = std::find_if(t.name.begin(), t.name.end(),
                                       [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
      t.family.assign(t.name.begin(), digits);
      const bool letters =
          std::all_of(t.name.begin(), digits, [](char c) { return std::isupper(static_cast<unsigned char>(c)); });
      const bool numbers =
          std::all_of(digits, t.name.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); });
      if (t.family.empty() || digits == t.name.end() || !letters || !numbers)
        r_.fail(entry["name"],
                "a trajectory name is its family's capital letters and a number (e.g. PA01), not '" + t.name + "'");
      if (!names.insert(t.name).second) r_.fail(entry["name"], "duplicate trajectory name '" + t.name + "'");
      t.posture = posture_name(entry["posture"]);
      t.speed = r_.integer(entry["speed"], "speed (a level)", 1, d_.levels());
      for (const auto& i : r_.sequence(entry["sequence"], "sequence of " + t.name)) t.items.push_back(item(i, t));
      if (entry["description"]) {
        t.description = r_.scalar(entry["description"], "description");
      } else {
        t.description = "from " + t.posture + ":";
        for (std::size_t k = 0; k < t.items.size(); ++k) t.description += (k ? "; " : " ") + t.items[k].summary;
      }
      d_.trajectories.push_back(std::move(t));
    }
  }

  Design& d_;
  const Reader& r_;
  int n_;
  std::map<std::string, std::vector<PrimitiveSpec>> patterns_;
};

}  // namespace

Design read_design(const std::filesystem::path& yaml, const std::vector<JointInfo>& joints) {
  const std::string file = yaml.string();
  if (joints.empty()) throw DataError(file, 0, "the robot has no joints");
  Design d;
  d.path = yaml;
  d.joints = joints;
  for (const auto& joint : joints) {
    d.joint_names.emplace_back(joint.name);
    // Angles in the file are in degrees; a prismatic joint has no unit in this format.
    if (joint.type != JointType::Revolute)
      throw DataError(file, 0,
                      "joint " + d.joint_names.back() + " is prismatic; trajectory designs cover revolute joints");
  }
  if (!std::filesystem::is_regular_file(yaml))
    throw DataError(file, 0, "cannot read the trajectory design: no such file");
  const YAML::Node root = io::load_yaml_file(yaml);
  const Reader reader(file, static_cast<int>(joints.size()));
  DesignReader(d, reader).read(root);
  return d;
}

}  // namespace symoro::trajectory
