#include "symoro/io/parameters_yaml.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "symoro/error.hpp"
#include "symoro/io/digest.hpp"
#include "symoro/io/number_text.hpp"
#include "symoro/io/yaml_keys.hpp"

namespace symoro::io {

namespace {

// The file's top level, a map: a CSV given as --params read as one scalar, and the next lookup
// said "operator[] call on a scalar".
YAML::Node parameters_root(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw DataError(path, 0, "not found");
  const YAML::Node root = load_yaml_file(path);
  if (!root.IsMap())
    throw DataError(
        path, 1,
        "not a parameters file: a YAML map with a 'parameters:' list (a study's report/parameters.yaml) "
        "was expected" +
            std::string(path.size() > 4 && path.compare(path.size() - 4, 4, ".csv") == 0 ? "; a .csv is not read here"
                                                                                         : ""));
  return root;
}

}  // namespace

Eigen::VectorXd read_parameters_yaml(const std::string& path, const std::vector<std::string>& names) {
  const YAML::Node root = parameters_root(path);
  const auto line = [](const YAML::Node& n) { return n.Mark().is_null() ? 0 : n.Mark().line + 1; };
  const YAML::Node list = root["parameters"];
  if (!list || !list.IsSequence()) throw DataError(path, 0, "no 'parameters:' list (a study's report/parameters.yaml)");
  std::map<std::string, std::pair<double, int>> values;
  for (const YAML::Node& p : list) {
    if (!p.IsMap() || !p["name"] || !p["value"]) throw DataError(path, line(p), "a parameter needs name and value");
    double v;
    try {
      v = p["value"].as<double>();
    } catch (const YAML::Exception&) {
      throw DataError(path, line(p["value"]), "value: expected a number");
    }
    if (!std::isfinite(v)) throw DataError(path, line(p["value"]), "value: expected a finite number");
    const std::string name = p["name"].as<std::string>();
    if (std::find(names.begin(), names.end(), name) == names.end())
      throw DataError(path, line(p), fmt::format("parameter '{}' is not one of the identified model's", name));
    values[name] = {v, line(p)};
  }
  Eigen::VectorXd phi(static_cast<Eigen::Index>(names.size()));
  for (std::size_t i = 0; i < names.size(); ++i) {
    const auto it = values.find(names[i]);
    if (it == values.end())
      throw DataError(path, line(list), fmt::format("parameter '{}' is missing ({} expected)", names[i], names.size()));
    phi(static_cast<Eigen::Index>(i)) = it->second.first;
  }
  return phi;
}

bool parameters_accepted(const std::string& path) {
  const YAML::Node root = parameters_root(path);
  const YAML::Node flag = root["accepted"];
  if (!flag) return false;
  try {
    return flag.as<bool>();
  } catch (const YAML::Exception&) {
    throw DataError(path, flag.Mark().line + 1, "accepted: expected true or false");
  }
}

std::optional<double> parameters_torque_delay(const std::string& path) {
  const YAML::Node root = parameters_root(path);
  const YAML::Node n = root["torque_delay_ms"];
  if (!n) return std::nullopt;
  double ms = std::numeric_limits<double>::quiet_NaN();
  try {
    ms = n.as<double>();
  } catch (const YAML::Exception&) {
  }
  if (!std::isfinite(ms) || std::abs(ms) > 1000)
    throw DataError(path, n.Mark().line + 1, "torque_delay_ms: expected a number of ms from -1000 to 1000");
  return ms / 1000;
}

std::string parameters_digest(const std::string& robot, const std::string& model, bool accepted,
                              const std::vector<std::string>& names, const Eigen::VectorXd& values) {
  std::string text = fmt::format("symoro-parameters 1\n{}\n{}\n{}\n", robot, model, accepted);
  for (std::size_t i = 0; i < names.size() && static_cast<Eigen::Index>(i) < values.size(); ++i)
    text += names[i] + " " + number_text(values(static_cast<Eigen::Index>(i))) + "\n";
  return digest_of(text);
}

ParametersIntegrity parameters_integrity(const std::string& path, const std::vector<std::string>& names) {
  const Eigen::VectorXd phi = read_parameters_yaml(path, names);
  const bool accepted = parameters_accepted(path);
  const YAML::Node root = parameters_root(path);  // read and checked above
  const auto text = [&](const char* key) {
    const YAML::Node n = root[key];
    return n && n.IsScalar() ? n.as<std::string>() : std::string();
  };
  const std::string saved = text("digest");
  if (saved.empty()) return {false, "it has no 'digest:' (identify writes one; an edited or hand-made file has none)"};
  const std::string actual = parameters_digest(text("robot"), text("model"), accepted, names, phi);
  if (saved != actual)
    return {false,
            fmt::format("its content does not match its digest (file {}, content {}): it was edited after identify "
                        "wrote it",
                        saved, actual)};
  return {true, ""};
}

}  // namespace symoro::io
