#include "symoro/control/description.hpp"

#include <cmath>
#include <vector>
#include <string>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "symoro/error.hpp"
#include "symoro/io/yaml_keys.hpp"

namespace symoro::control {

FfpdGains ControllerDescription::gains() const {
  return FfpdGains::from_bandwidth(period, pseudo_derivative_time, realization_inertia, realization_damping, bandwidth,
                                   damping_ratio);
}

namespace {

class Reader {
 public:
  Reader(std::string file, int joints) : file_(std::move(file)), n_(joints) {}

  [[noreturn]] void fail(const YAML::Node& node, const std::string& message) const {
    throw DataError(file_, node.IsDefined() ? static_cast<int>(node.Mark().line) + 1 : 0, message);
  }
  void keys(const YAML::Node& map, const std::string& where, const std::vector<std::string>& allowed) const {
    if (!map.IsMap()) fail(map, where + " must be a map");
    io::check_keys(map, allowed, file_, where);
    for (const auto& k : allowed)
      if (!map[k].IsDefined()) fail(map, fmt::format("{} lacks '{}'", where, k));
  }
  double number(const YAML::Node& node, const std::string& what, bool allow_zero) const {
    double v = 0;
    if (!node.IsScalar()) fail(node, what + " must be a number");
    try {
      std::size_t used = 0;
      v = std::stod(node.Scalar(), &used);
      if (used != node.Scalar().size()) throw std::invalid_argument(node.Scalar());
    } catch (const std::logic_error&) {
      fail(node, fmt::format("{} must be a number, not '{}'", what, node.Scalar()));
    }
    if (!std::isfinite(v) || v < 0 || (!allow_zero && v == 0))
      fail(node, fmt::format("{} must be {} (got {})", what, allow_zero ? "finite and >= 0" : "finite and > 0",
                             node.Scalar()));
    return v;
  }
  Eigen::VectorXd per_joint(const YAML::Node& node, const std::string& what, bool allow_zero) const {
    if (!node.IsSequence() || static_cast<int>(node.size()) != n_)
      fail(node, fmt::format("{} must list {} numbers, one per joint{}", what, n_,
                             node.IsSequence() ? fmt::format(" (it has {})", node.size()) : ""));
    Eigen::VectorXd v(n_);
    for (int j = 0; j < n_; ++j) v(j) = number(node[j], fmt::format("{} of joint {}", what, j + 1), allow_zero);
    return v;
  }

 private:
  std::string file_;
  int n_;
};

}  // namespace

ControllerDescription read_controller_description(const std::filesystem::path& path, int joints) {
  if (!std::filesystem::exists(path)) throw DataError(path.string(), 0, "no such file (the controller description)");
  const YAML::Node root = io::load_yaml_file(path);
  const Reader r(path.string(), joints);
  ControllerDescription c;
  c.path = path.string();
  try {
    r.keys(root, "the controller description",
           {"format", "period", "pseudo_derivative_time", "communication_delay", "realization", "bandwidth",
            "damping_ratio"});
    if (root["format"].as<std::string>() != "symoro-controller 1")
      r.fail(root["format"], "format must be 'symoro-controller 1'");
    c.period = r.number(root["period"], "period", false);
    c.pseudo_derivative_time = r.number(root["pseudo_derivative_time"], "pseudo_derivative_time", false);
    c.communication_delay = r.number(root["communication_delay"], "communication_delay", true);
    if (!(c.communication_delay < c.period))
      r.fail(root["communication_delay"], fmt::format("communication_delay {} s must be shorter than the period {} s",
                                                      c.communication_delay, c.period));
    r.keys(root["realization"], "realization", {"inertia", "damping"});
    c.realization_inertia = r.per_joint(root["realization"]["inertia"], "realization inertia", false);
    c.realization_damping = r.per_joint(root["realization"]["damping"], "realization damping", true);
    c.bandwidth = r.per_joint(root["bandwidth"], "bandwidth", false);
    c.damping_ratio = r.per_joint(root["damping_ratio"], "damping_ratio", false);
  } catch (const YAML::Exception& e) {
    throw DataError(path.string(), e.mark.line + 1, e.msg);
  }
  return c;
}

}  // namespace symoro::control
