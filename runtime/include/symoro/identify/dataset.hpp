// A dataset folder (dynid twin dataset, dynid import, or logs of the real arm with the same
// layout): its manifest dataset.yaml lists every run's trajectory, family, trial, CSV file and
// optional time window (docs/dataset.md). Runs of family "V" are held out.
#pragma once

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "symoro/io/log.hpp"

namespace symoro::identify {

struct DatasetRun {
  std::string trajectory, family;
  int trial = 1;
  std::filesystem::path file;  // absolute
  // The rows of the file this run is: window_start <= t < window_end (s, log time). Two runs
  // may share a file: a long run split into a fitting part and a held-out part.
  double window_start = -std::numeric_limits<double>::infinity();
  double window_end = std::numeric_limits<double>::infinity();
};

struct Dataset {
  std::filesystem::path dir;
  std::string robot;
  std::string twin;             // the twin configuration that made it ("" for measured data)
  std::string twin_overrides;   // the overrides it was made with (dynid twin dataset --config), or ""
  std::string source;           // "imported" (dynid import), or "" (not recorded)
  int robot_line = 0;           // line of "robot:" in dataset.yaml (0: none)
  std::vector<DatasetRun> runs;
  // The run of a trajectory and trial; throws DataError naming dataset.yaml when absent.
  const DatasetRun& find(const std::string& trajectory, int trial) const;
};

// Throws DataError (file and line) on a missing or malformed manifest or a listed file that
// does not exist.
Dataset read_dataset(const std::filesystem::path& dir);

// The run's log restricted to its window (time stamps kept as logged; meta.trajectory is the
// run's name, so that later errors name the run). DataError if the window is empty.
io::Log read_run_log(const DatasetRun& run);

// The same, checked against the model it is for: the log's robot (when its sidecar names one)
// and its joint count. DataError naming the log (its sidecar for the robot) otherwise.
io::Log read_run_log(const DatasetRun& run, const std::string& robot, int joints);

// DataError(dataset.yaml, line of robot:) when the dataset was made for another robot. A
// dataset that names no robot passes.
void check_dataset_robot(const Dataset& dataset, const std::string& robot);

}  // namespace symoro::identify
