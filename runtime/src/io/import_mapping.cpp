// The import mapping as a YAML file (dynid import --mapping, and the import.yaml record).
#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "symoro/error.hpp"
#include "symoro/io/import.hpp"

#include "import_detail.hpp"
#include "symoro/io/number_text.hpp"
#include "symoro/io/yaml_keys.hpp"

namespace symoro::io {

namespace {

constexpr std::array<const char*, 7> selector_keys = {"time", "q", "qd", "tau", "q_ref", "qd_ref", "qdd_ref"};

int line_of(const YAML::Node& n) { return n.Mark().is_null() ? 0 : n.Mark().line + 1; }

std::string& selector(ImportMapping& m, const std::string& key) {
  if (key == "time") return m.time;
  if (key == "q") return m.q;
  if (key == "qd") return m.qd;
  if (key == "tau") return m.tau;
  if (key == "q_ref") return m.q_ref;
  if (key == "qd_ref") return m.qd_ref;
  return m.qdd_ref;
}

const char* header_name(HeaderRow h) {
  return h == HeaderRow::present ? "yes" : h == HeaderRow::absent ? "no" : "auto";
}

const char* delimiter_name(Delimiter d) {
  switch (d) {
    case Delimiter::comma:
      return "comma";
    case Delimiter::semicolon:
      return "semicolon";
    case Delimiter::whitespace:
      return "whitespace";
    case Delimiter::automatic:
      break;
  }
  return "auto";
}

class MappingReader {
 public:
  MappingReader(std::string file, ImportMapping& m) : file_(std::move(file)), m_(m) {}
  [[noreturn]] void fail(const YAML::Node& n, const std::string& message) const {
    throw DataError(file_, line_of(n), message);
  }
  std::string scalar(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar()) fail(n, fmt::format("{}: expected a single value", key));
    return n.Scalar();
  }
  void selector_value(const std::string& key, const YAML::Node& n) {
    std::string text;
    if (n.IsSequence()) {  // a list of names or positions, as "a,b,c" on the command line
      for (const YAML::Node& item : n) text += (text.empty() ? "" : ",") + scalar(item, key);
    } else {
      text = scalar(n, key);
    }
    if (text.empty()) fail(n, fmt::format("{}: empty column selector", key));
    selector(m_, key) = text;
  }
  void units(const YAML::Node& n) {
    if (!n.IsMap()) fail(n, "units: expected a map with time, angle and torque_scale");
    check_keys(n, {"time", "angle", "torque_scale"}, file_, "units");
    for (const auto& e : n) {
      const std::string key = scalar(e.first, "units");
      const std::string value = scalar(e.second, "units." + key);
      m_.lines["units." + key] = line_of(e.first);
      if (key == "time") {
        m_.time_unit = parse_time_unit(value, e.second);
      } else if (key == "angle") {
        if (value == "rad")
          m_.angle_unit = AngleUnit::rad;
        else if (value == "deg")
          m_.angle_unit = AngleUnit::deg;
        else
          fail(e.second, fmt::format("units.angle: '{}' is neither rad nor deg", value));
      } else if (key == "torque_scale") {
        double v = 0;
        if (parse_number(value, v) != NumberParse::ok || !std::isfinite(v) || v == 0)
          fail(e.second, fmt::format("units.torque_scale: '{}' is not a finite non-zero number", value));
        m_.torque_scale = v;
      } else {
        fail(e.first, fmt::format("units: unknown key '{}' (time, angle, torque_scale)", key));
      }
    }
  }
  TimeUnit parse_time_unit(const std::string& value, const YAML::Node& n) const {
    for (TimeUnit u : {TimeUnit::s, TimeUnit::ms, TimeUnit::us, TimeUnit::ns})
      if (value == detail::time_unit_name(u)) return u;
    fail(n, fmt::format("units.time: '{}' is not one of s, ms, us, ns", value));
  }

 private:
  std::string file_;
  ImportMapping& m_;
};

}  // namespace

ImportMapping read_import_mapping(const std::filesystem::path& yaml) {
  ImportMapping m;
  m.origin = yaml.string();
  if (!std::filesystem::is_regular_file(yaml)) throw DataError(m.origin, 0, "cannot read the mapping file");
  const YAML::Node root = load_yaml_file(yaml);
  MappingReader reader(m.origin, m);
  if (!root.IsMap()) reader.fail(root, "the mapping is not a map of keys (time, q, qd, tau, ..., units)");
  // "imported": import.yaml's record of what was imported.
  check_keys(root, {"time", "q", "qd", "tau", "q_ref", "qd_ref", "qdd_ref", "units", "header", "delimiter", "imported"},
             m.origin, "the mapping");
  for (const auto& e : root) {
    const std::string key = reader.scalar(e.first, "key");
    if (m.lines.count(key)) reader.fail(e.first, fmt::format("key '{}' appears twice", key));
    m.lines[key] = line_of(e.first);
    if (std::find(selector_keys.begin(), selector_keys.end(), key) != selector_keys.end()) {
      reader.selector_value(key, e.second);
    } else if (key == "units") {
      reader.units(e.second);
    } else if (key == "header") {
      const std::string v = reader.scalar(e.second, key);
      if (v == "auto")
        m.header = HeaderRow::automatic;
      else if (v == "yes" || v == "true")
        m.header = HeaderRow::present;
      else if (v == "no" || v == "false")
        m.header = HeaderRow::absent;
      else
        reader.fail(e.second, fmt::format("header: '{}' is not auto, yes or no", v));
    } else if (key == "delimiter") {
      const std::string v = reader.scalar(e.second, key);
      bool known = false;
      for (Delimiter d : {Delimiter::automatic, Delimiter::comma, Delimiter::semicolon, Delimiter::whitespace})
        if (v == delimiter_name(d)) m.delimiter = d, known = true;
      if (!known) reader.fail(e.second, fmt::format("delimiter: '{}' is not auto, comma, semicolon or whitespace", v));
    } else if (key != "imported") {  // import.yaml's record of what was imported
      reader.fail(e.first, fmt::format("unknown key '{}' (time, q, qd, tau, q_ref, qd_ref, qdd_ref, units, header, "
                                       "delimiter)",
                                       key));
    }
  }
  return m;
}

std::string import_mapping_yaml(const ImportMapping& m) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  for (const char* key : selector_keys) {
    const std::string& value = selector(const_cast<ImportMapping&>(m), key);
    if (!value.empty()) out << YAML::Key << key << YAML::Value << YAML::DoubleQuoted << value;
  }
  out << YAML::Key << "units" << YAML::Value << YAML::Flow << YAML::BeginMap;
  out << YAML::Key << "time" << YAML::Value << detail::time_unit_name(m.time_unit);
  out << YAML::Key << "angle" << YAML::Value << (m.angle_unit == AngleUnit::deg ? "deg" : "rad");
  out << YAML::Key << "torque_scale" << YAML::Value << number_text(m.torque_scale) << YAML::EndMap;
  out << YAML::Key << "header" << YAML::Value << header_name(m.header);
  out << YAML::Key << "delimiter" << YAML::Value << delimiter_name(m.delimiter);
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

namespace detail {

const char* time_unit_name(TimeUnit u) {
  switch (u) {
    case TimeUnit::s:
      return "s";
    case TimeUnit::ms:
      return "ms";
    case TimeUnit::us:
      return "us";
    case TimeUnit::ns:
      return "ns";
  }
  return "s";
}

double time_divisor(TimeUnit u) {
  switch (u) {
    case TimeUnit::s:
      return 1;
    case TimeUnit::ms:
      return 1e3;
    case TimeUnit::us:
      return 1e6;
    case TimeUnit::ns:
      return 1e9;
  }
  return 1;
}

}  // namespace detail

}  // namespace symoro::io
