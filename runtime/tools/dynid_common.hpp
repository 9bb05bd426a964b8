// Shared pieces of the dynid subcommands: where robot folders are, usage errors, and a progress
// display for long batches. Included by every generated unit: CLI11 is only forward-declared.
#pragma once

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "symoro/model_info.hpp"

namespace CLI {
class App;
}  // namespace CLI

namespace symoro::dynid {

struct Common {
  std::string robot;   // the robot's name (its folder's)
  std::string folder;  // --robot given as a folder (robots/my_arm, ./arm): that folder
  std::string robots_dir = SYMORO_DEFAULT_ROBOTS_DIR;
  std::string design;  // --design: a trajectory design file instead of the robot's own
  std::filesystem::path robot_dir() const {
    return folder.empty() ? std::filesystem::path(robots_dir) / robot : std::filesystem::path(folder);
  }
  // The trajectory design commands read: --design, else robots/<robot>/trajectories.yaml.
  std::filesystem::path design_path() const {
    return design.empty() ? robot_dir() / "trajectories.yaml" : std::filesystem::path(design);
  }
};

// --robot (required) and --robots-dir, declared once for every command that reads a robot folder.
// --robot takes a name under --robots-dir or a folder (a path with a '/'): its name is the
// folder's.
template <class App>
void add_robot_options(App* cmd, Common& common,
                       const std::string& robot_help =
                           "Robot: a folder name under robots/, or a robot folder "
                           "(robots/my_arm, ./my_arm)") {
  cmd->add_option("--robot", common.robot, robot_help)->required()->transform([&common](std::string v) {
    if (v.find('/') == std::string::npos) return v;
    common.folder = v;
    std::filesystem::path p(v);
    if (!p.has_filename()) p = p.parent_path();  // robots/my_arm/
    return p.filename().string();
  });
  cmd->add_option("--robots-dir", common.robots_dir, "Where the robot folders are");
}

// An error in the command's use (unknown robot, missing file): printed without a stack.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Counts finished items on stderr; redraws one line on a terminal, prints lines otherwise.
class Progress {
 public:
  Progress(int total, std::string what) : total_(total), what_(std::move(what)), start_(clock::now()) {}
  void done(const std::string& item, const std::string& detail) {
    std::lock_guard<std::mutex> lock(m_);
    ++count_;
    const double elapsed = std::chrono::duration<double>(clock::now() - start_).count();
    const double eta = count_ > 0 ? elapsed / count_ * (total_ - count_) : 0;
    std::fprintf(stderr, "%s[%*d/%d] %s %-10s %s  elapsed %.0f s, eta %.0f s%s", tty_ ? "\r\033[K" : "", width(),
                 count_, total_, what_.c_str(), item.c_str(), detail.c_str(), elapsed, eta,
                 tty_ && count_ < total_ ? "" : "\n");
    std::fflush(stderr);
  }

 private:
  using clock = std::chrono::steady_clock;
  int width() const { return static_cast<int>(std::to_string(total_).size()); }
  int total_, count_ = 0;
  std::string what_;
  clock::time_point start_;
  std::mutex m_;
  bool tty_ = isatty_stderr();
  static bool isatty_stderr();
};

// robot.yaml's `nominal:` standard parameters (symoroc model writes a URDF's there) in the
// order of `standard`, a variant's effect parameters 0; false when robot.yaml has none. A
// UsageError names the parameters it lacks. (dynid_robot_folder.cpp)
bool nominal_standard_parameters(const Common& common, const std::vector<StandardParameterInfo>& standard,
                                 std::vector<double>& values);

void add_compare_commands(CLI::App& app, Common& common);
void add_twin_commands(CLI::App& app, Common& common);
void add_trajectory_commands(CLI::App& app, Common& common);
void add_excite_commands(CLI::App& app, Common& common);
void add_preprocess_commands(CLI::App& app, Common& common);
void add_identify_commands(CLI::App& app, Common& common);
void add_diagnose_commands(CLI::App& app, Common& common);
void add_control_commands(CLI::App& app, Common& common);
void add_import_commands(CLI::App& app, Common& common);
void add_observer_commands(CLI::App& app, Common& common);
void add_payload_commands(CLI::App& app, Common& common);
void add_export_commands(CLI::App& app, Common& common);
void add_predict_commands(CLI::App& app, Common& common);

}  // namespace symoro::dynid
