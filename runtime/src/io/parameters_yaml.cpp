#include "symoro/io/parameters_yaml.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "symoro/error.hpp"
#include "symoro/io/yaml_keys.hpp"

namespace symoro::io {

Eigen::VectorXd read_parameters_yaml(const std::string& path, const std::vector<std::string>& names) {
  if (!std::filesystem::is_regular_file(path)) throw DataError(path, 0, "not found");
  const YAML::Node root = load_yaml_file(path);
  const auto line = [](const YAML::Node& n) { return n.Mark().is_null() ? 0 : n.Mark().line + 1; };
  const YAML::Node list = root.IsMap() ? root["parameters"] : YAML::Node();
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
    if (it == values.end()) throw DataError(path, line(list), fmt::format("parameter '{}' is missing ({} expected)", names[i], names.size()));
    phi(static_cast<Eigen::Index>(i)) = it->second.first;
  }
  return phi;
}

bool parameters_accepted(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw DataError(path, 0, "not found");
  const YAML::Node root = load_yaml_file(path);
  const YAML::Node flag = root["accepted"];
  if (!flag) return false;
  try {
    return flag.as<bool>();
  } catch (const YAML::Exception&) {
    throw DataError(path, flag.Mark().line + 1, "accepted: expected true or false");
  }
}

}  // namespace symoro::io
