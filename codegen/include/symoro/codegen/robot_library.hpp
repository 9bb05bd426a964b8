// A robot as a small shared library (symoro/robot_abi.h): its headers generated from the robot
// folder, instantiated in double by one unit per model, compiled with the compiler and flags the
// project was configured with, into a cache keyed by the digest of the generated code, the
// compiler and the flags. `symoroc build`, dynid and the Python module build through here on first
// use; the runtime loads the result (symoro/robot/robot_library.hpp).
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace symoro::codegen {

// The compiler a robot library is built with.
struct RobotToolchain {
  std::string compiler;                   // a path, or a name looked up on PATH
  std::vector<std::string> flags;         // compile flags (-O3 -std=c++17 -fPIC ...)
  std::vector<std::string> include_dirs;  // symoro's headers (robot_abi.h, scalar.hpp, ...), Eigen

  // The compiler and flags the project was configured with (recorded by CMake), SYMORO_CXX
  // naming another compiler; symoro's headers found beside the running program when it is
  // installed (<prefix>/include), else in the source tree it was built from; SYMORO_INCLUDE_DIR
  // names them explicitly.
  static RobotToolchain configured();
  // The compiler's identity for the cache key: its resolved path and `--version` first line.
  // Throws BuildError when the compiler cannot be found or run.
  std::string identity() const;
};

struct RobotLibraryOptions {
  RobotToolchain toolchain = RobotToolchain::configured();
  std::filesystem::path cache_dir;  // empty: default_robot_cache_dir()
  int jobs = 0;                     // parallel compiles; 0: the machine's cores
  bool force = false;               // rebuild even when the cache has it
  // When set: the models' objects also go, partially linked, into this one object file, for a
  // program that links the robot's kernels statically (symoro::<robot>_identification).
  std::filesystem::path objects;
  std::function<void(const std::string&)> progress;  // one line per step, when set
};

struct RobotLibraryBuild {
  std::filesystem::path library;  // <cache>/<robot>-<key>/lib<robot>.so
  std::string robot, code_digest, key;
  int models = 0;
  bool built = false;  // false: taken from the cache
  double generate_seconds = 0, compile_seconds = 0;
};

// A robot library that could not be built: the compiler is missing, or it failed (the message
// carries the command and the compiler's last lines; the whole log is in the build folder).
class BuildError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// $SYMORO_CACHE_DIR, else $XDG_CACHE_HOME/symoro/robots, else ~/.cache/symoro/robots.
std::filesystem::path default_robot_cache_dir();

// Generates robot_dir's code (errors as symoroc generate's: file, line, column) and returns its
// library, building it into the cache when it is not there yet. Concurrent builds of one robot
// are safe: each builds in a folder of its own and the first to finish is kept.
RobotLibraryBuild build_robot_library(const std::filesystem::path& robot_dir, const RobotLibraryOptions& options = {});

}  // namespace symoro::codegen
