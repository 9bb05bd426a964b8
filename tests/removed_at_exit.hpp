// A path under the system's temporary directory that the test program removes when it ends (a
// GoogleTest environment's TearDown): the suite leaves no file behind in /tmp, run after run.
// Name it with the process id, as the programs' tests run one process each.
#pragma once

#include <filesystem>
#include <set>
#include <string>
#include <system_error>

#include <gtest/gtest.h>

namespace symoro::test {

inline std::filesystem::path removed_at_exit(const std::string& name) {
  struct Removal : ::testing::Environment {
    std::set<std::filesystem::path> paths;
    void TearDown() override {
      for (const auto& p : paths) {
        std::error_code ignored;  // gone already, or never made: nothing to do
        std::filesystem::remove_all(p, ignored);
      }
    }
  };
  static Removal* const removal = static_cast<Removal*>(::testing::AddGlobalTestEnvironment(new Removal));
  const std::filesystem::path p = std::filesystem::temp_directory_path() / name;
  removal->paths.insert(p);
  return p;
}

}  // namespace symoro::test
