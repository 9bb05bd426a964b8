#include "log_sidecar.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <set>
#include <type_traits>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "cell_text.hpp"
#include "symoro/error.hpp"
#include "symoro/io/number_text.hpp"
#include "symoro/io/text_file.hpp"
#include "symoro/io/yaml_keys.hpp"

namespace symoro::io::detail {

namespace {

constexpr std::array<std::string_view, 12> sidecar_keys = {"format", "robot",  "trajectory",  "trial",
                                                           "seed",   "source", "sample_time", "samples",
                                                           "joints", "units",  "notes",       "velocity"};
// Keys a sidecar may leave out (everything else the writer always writes is required).
// "velocity" is written only when differentiated, so older sidecars stay byte for byte the same.
constexpr std::array<std::string_view, 2> optional_keys = {"notes", "velocity"};

int line_of(const YAML::Node& node) {
  const YAML::Mark mark = node.Mark();
  return mark.is_null() ? 0 : mark.line + 1;
}

// Reads one sidecar's values, each error placed at the line of the offending node.
class SidecarReader {
 public:
  explicit SidecarReader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const YAML::Node& node, const std::string& message) const {
    throw DataError(file_, line_of(node), message);
  }

  std::string text(const YAML::Node& node, std::string_view key) const {
    if (node.IsNull()) return {};  // "notes:" with nothing after it
    if (!node.IsScalar()) fail(node, fmt::format("{}: expected a single value", key));
    return node.Scalar();
  }

  template <class Integer>
  Integer integer(const YAML::Node& node, std::string_view key) const {
    const std::string s = text(node, key);
    Integer value{};
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (s.empty() || ec != std::errc() || ptr != s.data() + s.size())
      fail(node, fmt::format("{}: expected a whole number{}, got '{}'", key, std::is_signed_v<Integer> ? "" : " >= 0",
                             shown_text(s)));
    return value;
  }

  double number(const YAML::Node& node, std::string_view key) const {
    const std::string s = text(node, key);
    double value = 0;
    if (parse_number(s, value) != NumberParse::ok || !std::isfinite(value))
      fail(node, fmt::format("{}: expected a finite number, got '{}'", key, shown_text(s)));
    return value;
  }

 private:
  std::string file_;
};

}  // namespace

Sidecar read_sidecar(const std::filesystem::path& yaml) {
  Sidecar sidecar;
  sidecar.file = yaml.string();
  const std::string& file = sidecar.file;
  const std::string content = read_text_file(yaml, "missing or unreadable metadata sidecar (every log CSV needs one)");

  const YAML::Node root = load_yaml_text(content, file);
  if (!root.IsMap()) throw DataError(file, line_of(root), "the metadata sidecar is not a map of keys");
  check_keys(root, std::vector<std::string>(sidecar_keys.begin(), sidecar_keys.end()), file, "the metadata sidecar");

  const SidecarReader reader(file);
  std::map<std::string, YAML::Node, std::less<>> values;
  std::map<std::string, int, std::less<>> key_lines;
  for (const auto& entry : root) {
    const std::string key = entry.first.IsScalar() ? entry.first.Scalar() : std::string();
    if (std::find(sidecar_keys.begin(), sidecar_keys.end(), key) == sidecar_keys.end())
      reader.fail(entry.first, fmt::format("unknown key '{}' in the metadata sidecar", key));
    if (!values.emplace(key, entry.second).second) reader.fail(entry.first, fmt::format("key '{}' appears twice", key));
    key_lines[key] = line_of(entry.first);
  }
  for (std::string_view key : sidecar_keys)
    if (values.find(key) == values.end() &&
        std::find(optional_keys.begin(), optional_keys.end(), key) == optional_keys.end())
      throw DataError(file, 0, fmt::format("the metadata sidecar has no '{}'", key));
  const auto value = [&](std::string_view key) { return values.find(key)->second; };

  const YAML::Node format = value("format");
  const std::string format_text = reader.text(format, "format");
  if (format_text != log_format) {
    if (format_text.rfind("symoro-log ", 0) == 0)
      reader.fail(format,
                  fmt::format("unsupported log format version '{}' (this reader reads '{}')", format_text, log_format));
    reader.fail(format, fmt::format("format is '{}', not '{}': not a symoro log sidecar", format_text, log_format));
  }

  LogMetadata& meta = sidecar.meta;
  meta.robot = reader.text(value("robot"), "robot");
  if (meta.robot.empty()) reader.fail(value("robot"), "robot: the robot name is empty");
  meta.trajectory = reader.text(value("trajectory"), "trajectory");
  meta.trial = reader.integer<int>(value("trial"), "trial");
  if (meta.trial < 0) reader.fail(value("trial"), fmt::format("trial: {} is negative", meta.trial));
  meta.seed = reader.integer<std::uint64_t>(value("seed"), "seed");
  meta.source = reader.text(value("source"), "source");
  if (!is_known_source(meta.source))
    reader.fail(value("source"),
                fmt::format("source: unknown source '{}' (expected twin, robot or reference)", meta.source));
  meta.sample_time = reader.number(value("sample_time"), "sample_time");
  if (meta.sample_time <= 0)
    reader.fail(value("sample_time"), fmt::format("sample_time: {} s is not positive", number_text(meta.sample_time)));
  if (values.count("notes")) meta.notes = reader.text(value("notes"), "notes");
  if (values.count("velocity")) {
    const std::string velocity = reader.text(value("velocity"), "velocity");
    if (velocity == "measured")
      meta.velocity = Velocity::measured;
    else if (velocity == "differentiated")
      meta.velocity = Velocity::differentiated;
    else
      reader.fail(value("velocity"), fmt::format("velocity: '{}' is neither measured nor differentiated", velocity));
  }

  const YAML::Node samples = value("samples");
  sidecar.samples = reader.integer<long long>(samples, "samples");
  sidecar.samples_line = key_lines["samples"];
  // 0 is a run that stopped before its first row (its notes say why); read_log refuses it then.
  if (sidecar.samples < 0) reader.fail(samples, fmt::format("samples: {} is negative", sidecar.samples));

  const YAML::Node joints = value("joints");
  if (!joints.IsSequence() || joints.size() == 0)
    reader.fail(joints, "joints: expected a non-empty list of joint names");
  std::set<std::string> seen;
  for (const YAML::Node& joint : joints) {
    std::string name = reader.text(joint, "joints");
    if (name.empty()) reader.fail(joint, fmt::format("joints: joint {} has an empty name", meta.joints.size() + 1));
    if (!seen.insert(name).second) reader.fail(joint, fmt::format("joints: joint name '{}' appears twice", name));
    meta.joints.push_back(std::move(name));
  }

  const YAML::Node units = value("units");
  sidecar.units_line = key_lines["units"];  // the map's own mark is its first entry
  if (!units.IsMap()) reader.fail(units, "units: expected a map from quantity (time, q, ...) to unit");
  std::vector<std::string> quantities;
  for (Group g : all_groups) quantities.emplace_back(group_name(g));
  check_keys(units, quantities, file, "units");
  for (const auto& entry : units) {
    const std::string key = entry.first.IsScalar() ? entry.first.Scalar() : std::string();
    const auto group = group_named(key);
    if (!group) reader.fail(entry.first, fmt::format("units: unknown quantity '{}'", key));
    const std::string unit = reader.text(entry.second, "units");
    if (unit != group_unit(*group))
      reader.fail(entry.second, fmt::format("units: {} is in '{}', but a log holds SI values: expected '{}'", key, unit,
                                            group_unit(*group)));
    if (!sidecar.unit_lines.emplace(*group, line_of(entry.first)).second)
      reader.fail(entry.first, fmt::format("units: '{}' appears twice", key));
  }
  return sidecar;
}

void check_units_cover(const Sidecar& sidecar, const std::vector<Group>& groups) {
  for (Group g : groups)
    if (sidecar.unit_lines.count(g) == 0)
      throw DataError(sidecar.file, sidecar.units_line,
                      fmt::format("units: no unit for {} (expected '{}')", group_name(g), group_unit(g)));
}

std::string sidecar_text(const Log& log, const std::string& file) {
  const LogMetadata& meta = log.meta;
  YAML::Emitter out;
  // Strings are double-quoted so that names such as "null", "1" or "yes" read back as text.
  out << YAML::BeginMap;
  out << YAML::Key << "format" << YAML::Value << std::string(log_format);
  out << YAML::Key << "robot" << YAML::Value << YAML::DoubleQuoted << meta.robot;
  out << YAML::Key << "trajectory" << YAML::Value << YAML::DoubleQuoted << meta.trajectory;
  out << YAML::Key << "trial" << YAML::Value << meta.trial;
  out << YAML::Key << "seed" << YAML::Value << meta.seed;
  out << YAML::Key << "source" << YAML::Value << YAML::DoubleQuoted << meta.source;
  out << YAML::Key << "sample_time" << YAML::Value << number_text(meta.sample_time);
  out << YAML::Key << "samples" << YAML::Value << log.samples();
  out << YAML::Key << "joints" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (const std::string& joint : meta.joints) out << YAML::DoubleQuoted << joint;
  out << YAML::EndSeq;
  out << YAML::Key << "units" << YAML::Value << YAML::BeginMap;
  for (Group g : groups_of(log))
    out << YAML::Key << std::string(group_name(g)) << YAML::Value << std::string(group_unit(g));
  out << YAML::EndMap;
  out << YAML::Key << "notes" << YAML::Value << YAML::DoubleQuoted << meta.notes;
  if (meta.velocity == Velocity::differentiated) out << YAML::Key << "velocity" << YAML::Value << "differentiated";
  out << YAML::EndMap;
  if (!out.good()) throw DataError(file, 0, "cannot write the metadata sidecar: " + out.GetLastError());
  return std::string(out.c_str()) + "\n";
}

}  // namespace symoro::io::detail
