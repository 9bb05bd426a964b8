// A robot folder at run time: its library found in the robot cache or built into it on first use
// (symoroc build's builder, codegen/robot_library.hpp, with the compiler symoro was configured
// with), then opened and checked against the folder (robot_library.hpp). Apart from the runtime
// area `robot`, which needs no compiler: it links the model compiler.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "symoro/robot/robot_library.hpp"

namespace symoro::robot {

struct LoadOptions {
  std::filesystem::path cache_dir;                   // empty: the default robot cache
  int jobs = 0;                                      // parallel compiles of a build; 0: the machine's cores
  std::function<void(const std::string&)> progress;  // build progress, when set
};

// The library of a robot folder: generated, found in the cache or built into it, opened and
// checked against the folder. Errors in the folder's files name file, line and column.
std::shared_ptr<const RobotLibrary> load_robot(const std::filesystem::path& robot_dir, const LoadOptions& options = {});

// A --robot argument as a folder: a path that names a folder (robots/my_arm, ./arm, /abs/arm) is
// itself; a bare name is robots_dir/<name>.
std::filesystem::path robot_folder(const std::string& robot, const std::filesystem::path& robots_dir);

}  // namespace symoro::robot
