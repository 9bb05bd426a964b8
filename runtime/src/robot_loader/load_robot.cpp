#include "symoro/robot/load_robot.hpp"

#include "symoro/codegen/robot_library.hpp"

namespace symoro::robot {
namespace fs = std::filesystem;

std::shared_ptr<const RobotLibrary> load_robot(const fs::path& robot_dir, const LoadOptions& options) {
  codegen::RobotLibraryOptions build;
  build.cache_dir = options.cache_dir;
  build.jobs = options.jobs;
  build.progress = options.progress;
  codegen::RobotLibraryBuild b;
  try {
    b = codegen::build_robot_library(robot_dir, build);
  } catch (const codegen::BuildError& e) {
    throw LoadError(e.what());
  }
  auto lib = RobotLibrary::open(b.library);
  lib->check_folder(robot_dir);
  return lib;
}

fs::path robot_folder(const std::string& robot, const fs::path& robots_dir) {
  const bool looks_like_path = robot.find('/') != std::string::npos || robot == "." || robot == "..";
  if (looks_like_path) return fs::path(robot);
  return robots_dir / robot;
}

}  // namespace symoro::robot
