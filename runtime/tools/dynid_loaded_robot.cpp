#include "dynid_loaded_robot.hpp"

#include <algorithm>
#include <filesystem>
#include <map>

#include <fmt/format.h>

#include "dynid_dispatch.hpp"
#include "symoro/identify/loaded_model.hpp"
#include "symoro/robot/load_robot.hpp"

namespace symoro::dynid {

namespace {

std::shared_ptr<const robot::RobotLibrary> library_of(const Common& common) {
  const std::filesystem::path dir = common.robot_dir();
  if (!std::filesystem::is_directory(dir)) {
    std::string known;
    for (const auto& r : robot_names()) known += (known.empty() ? "" : ", ") + r;
    throw UsageError(fmt::format("unknown robot '{}': {} is not a folder (robots compiled into this dynid: {}; any "
                                 "robot folder works with --robot path/to/folder)",
                                 common.robot, dir.string(), known));
  }
  if (!std::filesystem::exists(dir / "robot.yaml"))
    throw UsageError(fmt::format("{} is not a robot folder: it has no robot.yaml (symoroc model <robot>.urdf -o {} "
                                 "writes one)", dir.string(), dir.string()));
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

}  // namespace

std::string not_compiled(const Common& common) {
  std::string known;
  for (const auto& r : robot_names()) known += (known.empty() ? "" : ", ") + r;
  return fmt::format("robot '{}' ({}) is not compiled into this dynid (its robots: {}): this command needs a compiled "
                     "robot yet; import, identify, diagnose, predict, compare, excite and export run on any robot folder "
                     "through its robot library",
                     common.robot, common.robot_dir().string(), known);
}

bool compiled_robot(const Common& common) {
  const auto& names = robot_names();
  if (std::find(names.begin(), names.end(), common.robot) == names.end()) return false;
  if (common.folder.empty()) return true;
  std::error_code ec;
  return std::filesystem::equivalent(common.robot_dir(), std::filesystem::path(common.robots_dir) / common.robot, ec);
}

robot::ModelHandle loaded_model(const Common& common, const std::string& label) {
  const auto lib = library_of(common);
  try {
    return lib->model(label);
  } catch (const robot::LoadError& e) {
    throw UsageError(e.what());
  }
}

std::shared_ptr<const identify::IdentificationModel> loaded_identification_model(const Common& common,
                                                                                 const std::string& label) {
  const auto lib = library_of(common);
  try {
    return identify::identification_model(lib->model(label), lib->model(0));
  } catch (const robot::LoadError& e) {
    throw UsageError(e.what());
  }
}

}  // namespace symoro::dynid
