#include "dynid_robots.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "symoro/identify/loaded_model.hpp"
#include "symoro/io/parameters_yaml.hpp"
#include "symoro/io/yaml_keys.hpp"
#include "symoro/robot/load_robot.hpp"

namespace symoro::dynid {

namespace {

std::shared_ptr<const robot::RobotLibrary> library_of(const Common& common) {
  const std::filesystem::path dir = common.robot_dir();
  if (!std::filesystem::is_directory(dir)) {
    std::string known;
    for (const auto& r : robot_names()) known += (known.empty() ? "" : ", ") + r;
    throw UsageError(
        fmt::format("unknown robot '{}': {} is not a folder (robots compiled into this dynid: {}; any "
                    "robot folder works with --robot path/to/folder)",
                    common.robot, dir.string(), known));
  }
  if (!std::filesystem::exists(dir / "robot.yaml"))
    throw UsageError(
        fmt::format("{} is not a robot folder: it has no robot.yaml (symoroc model <robot>.urdf -o {} "
                    "writes one)",
                    dir.string(), dir.string()));
  // Once per command: its models (an export's and its full model, say) share the library.
  static std::map<std::string, std::shared_ptr<const robot::RobotLibrary>> loaded;
  if (const auto it = loaded.find(dir.string()); it != loaded.end()) return it->second;
  robot::LoadOptions lo;
  lo.progress = [](const std::string& line) { fmt::print(stderr, "{}\n", line); };
  try {
    return loaded[dir.string()] = robot::load_robot(dir, lo);
  } catch (const robot::LoadError& e) {
    throw UsageError(e.what());
  }
}

// A linked robot's model by label, as a robot library names them.
robot::ModelHandle linked_model(const Common& common, const robot::LinkedRobot& linked, const std::string& label) {
  if (label.empty()) return *linked.models[linked.identified];
  std::string list;
  for (const robot::ModelHandle* m : linked.models) {
    if (m->label() == label) return *m;
    list += (list.empty() ? "" : ", ") + m->label();
  }
  throw UsageError(
      fmt::format("robot '{}' has no compiled model '{}' (it has: {}); a variant just added to robot.yaml must be "
                  "generated (symoroc generate robots/{} -o generated) and dynid rebuilt",
                  common.robot, label, list, common.robot));
}

}  // namespace

trajectory::TrajectoryDesign read_design(const Common& common, const std::vector<JointInfo>& joints) {
  const std::filesystem::path path = common.design_path();
  if (common.design.empty() && !std::filesystem::exists(path))
    throw UsageError(
        fmt::format("robot '{}' has no trajectory design ({} not found): dynid excite --robot {} -o <folder> "
                    "designs one, which --design <folder>/trajectories.yaml then uses",
                    common.robot, path.string(), common.robot_dir().string()));
  return trajectory::TrajectoryDesign::read(path, joints);
}

bool compiled_robot(const Common& common) {
  if (!linked_robot(common.robot)) return false;
  if (common.folder.empty()) return true;
  std::error_code ec;
  return std::filesystem::equivalent(common.robot_dir(), std::filesystem::path(common.robots_dir) / common.robot, ec);
}

robot::ModelHandle robot_model(const Common& common, const std::string& label) {
  if (compiled_robot(common)) {
    // Once per folder: a command asks for several models (its own, the full one), each file
    // digested once.
    static std::set<std::string> checked;
    if (checked.insert(common.robot_dir().string()).second) check_robot_folder(common);
    return linked_model(common, *linked_robot(common.robot), label);
  }
  const auto lib = library_of(common);
  try {
    return lib->model(label);
  } catch (const robot::LoadError& e) {
    throw UsageError(e.what());
  }
}

std::shared_ptr<const identify::IdentificationModel> identification_model(const Common& common,
                                                                          const std::string& label) {
  return identify::identification_model(robot_model(common, label), full_model(common));
}

std::string parameters_model(const std::string& params, const std::string& model) {
  if (params == "nominal") return model;
  if (!std::filesystem::exists(params)) throw UsageError(params + ": not found");
  std::string in_file;
  try {
    const YAML::Node root = io::load_yaml_file(params);
    in_file = root["model"] ? root["model"].as<std::string>() : std::string();
  } catch (const YAML::Exception& e) {
    throw UsageError(params + ": invalid YAML: " + e.what());
  }
  if (in_file.empty()) in_file = "full";
  if (!model.empty() && model != in_file)
    throw UsageError(fmt::format("--model {}, but {} holds the parameters of model {}", model, params, in_file));
  return in_file;
}

Eigen::VectorXd parameters_phi(const Common& common, const robot::ModelHandle& model, const std::string& params) {
  if (params == "nominal") {
    std::vector<double> s;
    if (!nominal_standard_parameters(common, model.standard_parameters(), s))
      throw UsageError((common.robot_dir() / "robot.yaml").string() +
                       " has no nominal parameters (symoroc model writes them from a URDF): give --params "
                       "<study>/report/parameters.yaml");
    return model.base_from_standard(Eigen::Map<const Eigen::VectorXd>(s.data(), static_cast<Eigen::Index>(s.size())));
  }
  std::vector<std::string> names;
  for (const auto& p : model.parameters()) names.push_back(p.name);
  const io::ParametersIntegrity integrity = io::parameters_integrity(params, names);
  if (!integrity.intact) fmt::print(stderr, "warning: {}: {}\n", params, integrity.why);
  return io::read_parameters_yaml(params, names);
}

FitTiming fit_torque_delay(const std::string& params, std::optional<double> given_ms) {
  const std::optional<double> arm = params == "nominal" ? std::nullopt : io::parameters_torque_delay(params);
  if (!given_ms) {
    if (arm) return {*arm * 1000, "the arm's, from " + params};
    return {0, params == "nominal" ? "nominal parameters carry no timing" : params + " does not say the arm's"};
  }
  if (arm && std::abs(*arm * 1000 - *given_ms) > 1e-9)
    fmt::print(stderr,
               "warning: --torque-delay {:g} ms, but {} was identified at {:g} ms: the difference shows in the fit "
               "as inertia (docs/payload.md)\n",
               *given_ms, params, *arm * 1000);
  return {*given_ms, "given"};
}

}  // namespace symoro::dynid
