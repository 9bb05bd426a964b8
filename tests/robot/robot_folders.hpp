// The robot folders a test compiled once covers, each reached through its robot library: the
// shipped robots (robots/<name> for every name of SYMORO_TEST_ROBOTS, the build's list) and any
// folder in the environment's SYMORO_TEST_ROBOT_DIRS (':'-separated: a robot the suite has never
// seen, tools/run_tests.sh), whose library is built on first use. Libraries come from the test
// cache SYMORO_TEST_ROBOT_CACHE (the robot_libraries fixture builds the shipped robots').
#pragma once

#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "symoro/robot/load_robot.hpp"

namespace symoro::test {

inline std::vector<std::string> test_robot_folders() {
  std::vector<std::string> out;
  std::stringstream names(SYMORO_TEST_ROBOTS);
  for (std::string name; std::getline(names, name, ',');)
    if (!name.empty()) out.push_back(std::string(SYMORO_ROBOTS_DIR) + "/" + name);
  if (const char* extra = std::getenv("SYMORO_TEST_ROBOT_DIRS")) {
    std::stringstream dirs(extra);
    for (std::string dir; std::getline(dirs, dir, ':');)
      if (!dir.empty()) out.push_back(std::filesystem::absolute(dir).lexically_normal().string());
  }
  return out;
}

// The folder's library, loaded once per process.
inline std::shared_ptr<const robot::RobotLibrary> test_library(const std::string& folder) {
  static std::map<std::string, std::shared_ptr<const robot::RobotLibrary>> loaded;
  auto& lib = loaded[folder];
  if (!lib) {
    robot::LoadOptions o;
    o.cache_dir = SYMORO_TEST_ROBOT_CACHE;
    lib = robot::load_robot(folder, o);
  }
  return lib;
}

// A test's name for a folder: its last component (robots/ur5 -> ur5).
inline std::string folder_test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string name = std::filesystem::path(info.param).filename().string();
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
}

}  // namespace symoro::test
