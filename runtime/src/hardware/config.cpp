#include "symoro/hardware/config.hpp"

#include "symoro/dynamixel/control_table.hpp"

#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "symoro/error.hpp"
#include "symoro/io/text_file.hpp"
#include "symoro/io/yaml_keys.hpp"

namespace symoro::hardware {

std::vector<std::uint8_t> HardwareConfig::ids() const {
  std::vector<std::uint8_t> out;
  for (const auto& j : joints) out.push_back(j.id);
  return out;
}

namespace {

int line_of(const YAML::Node& n) { return n.Mark().is_null() ? 0 : n.Mark().line + 1; }

struct Reader {
  std::string file;
  [[noreturn]] void fail(const YAML::Node& at, const std::string& what) const {
    throw DataError(file, line_of(at), what);
  }
  YAML::Node need(const YAML::Node& map, const char* key, const std::string& where) const {
    const YAML::Node v = map[key];
    if (!v) fail(map, fmt::format("{}: missing '{}'", where, key));
    return v;
  }
  void keys(const YAML::Node& map, std::initializer_list<const char*> allowed, const std::string& where) const {
    if (!map.IsMap()) fail(map, where + ": expected a map");
    io::check_keys(map, std::vector<std::string>(allowed.begin(), allowed.end()), file, where);
  }
  double number(const YAML::Node& n, const std::string& what) const {
    if (!n.IsScalar()) fail(n, what + ": expected a number");
    try {
      const double v = n.as<double>();
      if (!std::isfinite(v)) fail(n, what + ": expected a finite number");
      return v;
    } catch (const YAML::Exception&) {
      fail(n, fmt::format("{}: expected a number, got '{}'", what, n.Scalar()));
    }
  }
  double positive(const YAML::Node& n, const std::string& what) const {
    const double v = number(n, what);
    if (!(v > 0)) fail(n, what + ": must be positive");
    return v;
  }
  long long integer(const YAML::Node& n, const std::string& what, long long lo, long long hi) const {
    const double v = number(n, what);
    if (v != std::floor(v) || v < lo || v > hi)
      fail(n, fmt::format("{}: expected a whole number in {}..{}, got '{}'", what, lo, hi, n.Scalar()));
    return static_cast<long long>(v);
  }
  std::string text(const YAML::Node& n, const std::string& what) const {
    if (!n.IsScalar()) fail(n, what + ": expected text");
    return n.Scalar();
  }
};

// bus: the baud rate, the servos' return delay, the loop's period.
void read_bus(const Reader& r, const YAML::Node& root, HardwareConfig& c) {
  const YAML::Node bus = r.need(root, "bus", "hardware.yaml");
  r.keys(bus, {"baud", "return_delay_time", "period"}, "bus");
  c.baud = static_cast<std::uint32_t>(r.integer(r.need(bus, "baud", "bus"), "bus.baud", 9600, 4'500'000));
  if (bus["return_delay_time"])
    c.return_delay_time = static_cast<int>(r.integer(bus["return_delay_time"], "bus.return_delay_time", 0, 254));
  if (bus["period"]) {
    c.period = r.number(bus["period"], "bus.period");
    if (!(c.period >= 0.0002 && c.period <= 0.02))
      r.fail(bus["period"],
             fmt::format("bus.period: {} s is outside [0.0002, 0.02] s: the loop runs at 50 Hz to 5 kHz", c.period));
  }
}

// models: each servo model's number, torque constant, current unit and limit, by name.
std::map<std::string, ServoModel> read_models(const Reader& r, const YAML::Node& root) {
  std::map<std::string, ServoModel> models;
  const YAML::Node ms = r.need(root, "models", "hardware.yaml");
  if (!ms.IsMap())
    r.fail(ms, "models: expected a map of model name to {model_number, torque_constant, current_unit, current_limit}");
  for (const auto& kv : ms) {
    ServoModel m;
    m.name = kv.first.as<std::string>();
    const std::string where = "models." + m.name;
    r.keys(kv.second, {"model_number", "torque_constant", "current_unit", "current_limit"}, where);
    m.model_number = static_cast<std::uint16_t>(
        r.integer(r.need(kv.second, "model_number", where), where + ".model_number", 0, 65535));
    m.torque_constant = r.positive(r.need(kv.second, "torque_constant", where), where + ".torque_constant");
    m.current_unit = r.positive(r.need(kv.second, "current_unit", where), where + ".current_unit");
    m.current_limit = r.positive(r.need(kv.second, "current_limit", where), where + ".current_limit");
    models[m.name] = m;
  }
  return models;
}

// joints: one entry per robot joint, in its order: its servo (ID, model), zero, direction and
// current limit.
void read_joints(const Reader& r, const YAML::Node& root, const std::map<std::string, ServoModel>& models,
                 const std::vector<JointInfo>& robot_joints, HardwareConfig& c) {
  const YAML::Node js = r.need(root, "joints", "hardware.yaml");
  if (!js.IsSequence()) r.fail(js, "joints: expected a list, one entry per joint");
  if (js.size() != robot_joints.size())
    r.fail(js, fmt::format("joints: {} entries, the robot has {} joints", js.size(), robot_joints.size()));
  std::set<int> ids;
  for (std::size_t i = 0; i < js.size(); ++i) {
    const YAML::Node j = js[i];
    const std::string where = fmt::format("joints[{}]", i + 1);
    r.keys(j, {"name", "id", "model", "zero", "direction", "current_limit"}, where);
    JointHardware h;
    h.name = r.text(r.need(j, "name", where), where + ".name");
    if (h.name != robot_joints[i].name)
      r.fail(j["name"], fmt::format("{}: joint '{}' here, the robot's joint {} is '{}'", where, h.name, i + 1,
                                    robot_joints[i].name));
    h.id = static_cast<std::uint8_t>(r.integer(r.need(j, "id", where), where + ".id", 0, 252));
    if (!ids.insert(h.id).second) r.fail(j["id"], fmt::format("{}: servo ID {} is used twice", where, int(h.id)));
    const std::string model = r.text(r.need(j, "model", where), where + ".model");
    const auto m = models.find(model);
    if (m == models.end())
      r.fail(j["model"], fmt::format("{}: unknown servo model '{}' (not under models:)", where, model));
    h.model = m->second;
    // Within one revolution of the encoder (4096 pulses): a zero turns away puts every reading
    // that far from the joint's limits.
    if (j["zero"]) h.zero = static_cast<std::int32_t>(r.integer(j["zero"], where + ".zero", 0, 4095));
    if (j["direction"]) {
      h.direction = static_cast<int>(r.integer(j["direction"], where + ".direction", -1, 1));
      if (h.direction == 0) r.fail(j["direction"], where + ".direction: expected 1 or -1");
    }
    h.current_limit = r.positive(r.need(j, "current_limit", where), where + ".current_limit");
    if (h.current_limit > h.model.current_limit)
      r.fail(j["current_limit"], fmt::format("{}.current_limit: {} A is beyond the {}'s {} A", where, h.current_limit,
                                             h.model.name, h.model.current_limit));
    c.joints.push_back(h);
  }
}

// safety: the watchdogs, each limit within the range that keeps it a limit, what a stop does.
void read_safety(const Reader& r, const YAML::Node& s, HardwareConfig& c) {
  r.keys(s,
         {"watchdog_cycles", "position_tolerance", "velocity_factor", "current_trip_factor", "approach_speed",
          "pre_roll", "at_stop", "hold_time", "bus_watchdog"},
         "safety");
  if (s["watchdog_cycles"])
    c.safety.watchdog_cycles =
        static_cast<int>(r.integer(s["watchdog_cycles"], "safety.watchdog_cycles", 1, kMaxWatchdogCycles));
  // Each limit within a range that keeps it a limit (safety_bound): 1e9 rad of tolerance or
  // 100 times the velocity limit would switch it off.
  const auto bounded = [&](const char* key, double& value) {
    if (!s[key]) return;
    const SafetyBound& b = safety_bound(key);
    const double v = r.number(s[key], std::string("safety.") + key);
    if (!(v >= b.lower && v <= b.upper) || (b.lower_open && v == b.lower))
      r.fail(s[key], fmt::format("safety.{}: {} is outside {}{}, {}] {}: {}", key, v, b.lower_open ? "(" : "[", b.lower,
                                 b.upper, b.unit, b.why));
    value = v;
  };
  bounded("position_tolerance", c.safety.position_tolerance);
  bounded("velocity_factor", c.safety.velocity_factor);
  bounded("current_trip_factor", c.safety.current_trip_factor);
  bounded("approach_speed", c.safety.approach_speed);
  bounded("pre_roll", c.safety.pre_roll);
  if (s["at_stop"]) {
    const std::string a = r.text(s["at_stop"], "safety.at_stop");
    if (a == "hold")
      c.safety.at_stop = StopAction::hold;
    else if (a == "torque_off")
      c.safety.at_stop = StopAction::torque_off;
    else
      r.fail(s["at_stop"], fmt::format("safety.at_stop: '{}', expected hold or torque_off", a));
  }
  bounded("hold_time", c.safety.hold_time);
  if (s["bus_watchdog"]) {
    const double w = r.number(s["bus_watchdog"], "safety.bus_watchdog");
    const double units = std::ceil(w / dynamixel::xseries::kBusWatchdogUnit - 1e-9);
    if (!(w == 0 || (units >= 1 && units <= 127)))
      r.fail(s["bus_watchdog"],
             fmt::format("safety.bus_watchdog: {} s; the servos' Bus Watchdog takes 0 (off) or 0.02 to 2.54 s", w));
    c.safety.bus_watchdog = w;
  }
}

}  // namespace

const char* to_string(StopAction action) { return action == StopAction::hold ? "hold" : "torque_off"; }

const SafetyBound& safety_bound(const std::string& key) {
  static const std::map<std::string, SafetyBound> bounds = {
      {"position_tolerance", {0, 0.2, false, "rad", "past robot.yaml's joint limits"}},
      {"velocity_factor", {0, 1.5, true, "", "times robot.yaml's velocity limits"}},
      {"current_trip_factor", {1, 3, false, "", "times the joints' current limits (commands are saturated at 1)"}},
      {"approach_speed", {0, 1, true, "rad/s", "towards the trajectory's start"}},
      {"pre_roll", {0, 10, false, "s", "holding the start posture"}},
      {"hold_time", {0, 600, true, "s", "holding the stop pose before torque off (as dynid control --hold-time)"}},
  };
  return bounds.at(key);
}

HardwareConfig read_hardware_config(const std::filesystem::path& path, const std::vector<JointInfo>& robot_joints) {
  HardwareConfig c;
  c.path = path.string();
  Reader r{c.path};
  const YAML::Node root =
      io::load_yaml_text(io::read_text_file(path, "not found (the robot's hardware description)"), c.path);
  if (!root.IsMap()) throw DataError(c.path, 1, "expected a map of keys");
  r.keys(root, {"format", "bus", "models", "joints", "safety"}, "hardware.yaml");
  const std::string format = r.text(r.need(root, "format", "hardware.yaml"), "format");
  if (format != "symoro-hardware 1")
    r.fail(root["format"], "format: expected 'symoro-hardware 1', got '" + format + "'");
  read_bus(r, root, c);
  read_joints(r, root, read_models(r, root), robot_joints, c);
  if (const YAML::Node s = root["safety"]) read_safety(r, s, c);
  return c;
}

}  // namespace symoro::hardware
