// A robot at run time: its library (symoro/robot_abi.h) opened, checked and kept loaded. The
// loader refuses a library of another ABI version, and one whose robot folder has changed since
// it was compiled, naming both sides. load_robot (load_robot.hpp) builds a folder's library into
// the cache on first use.
#pragma once

#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "symoro/robot/model_handle.hpp"
#include "symoro/robot_abi.h"

namespace symoro::robot {

// A robot library that cannot be used: not a robot library, another ABI version, a stale
// folder, or a build that failed (the message says which, and what to do).
class LoadError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class RobotLibrary : public std::enable_shared_from_this<RobotLibrary> {
 public:
  // Opens a library file (dlopen, kept loaded for the process) and checks its ABI version. The
  // same file opened twice is one RobotLibrary.
  static std::shared_ptr<const RobotLibrary> open(const std::filesystem::path& library);

  // Refuses (LoadError) when a file the library was generated from differs in robot_dir, or is
  // missing there: names the file and both digests.
  void check_folder(const std::filesystem::path& robot_dir) const;

  const std::filesystem::path& path() const { return path_; }
  const symoro_abi_robot& abi() const { return *abi_; }
  const std::string& robot() const { return robot_; }
  const std::string& code_digest() const { return code_digest_; }
  int model_count() const { return abi_->n_models; }
  std::vector<std::string> model_labels() const;  // "full", then the variants

  ModelHandle model(int index) const;
  // By label: "full", a variant's name, or "" for robot.yaml's `identified`; LoadError naming the
  // robot's models when it has none such.
  ModelHandle model(const std::string& label) const;

  RobotLibrary(std::filesystem::path path, const symoro_abi_robot* abi);

 private:
  std::filesystem::path path_;
  const symoro_abi_robot* abi_;
  std::string robot_, code_digest_;
};

}  // namespace symoro::robot
