// A dataset folder (dynid twin dataset, dynid import, or logs of the real arm with the same
// layout) and its manifest, dataset.yaml ("symoro-dataset 1", docs/dataset.md): every run's
// trajectory, family, trial, CSV file and optional time window, and how the folder was made.
// Runs of family "V" are held out. This file is the manifest's one reader and one writer.
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "symoro/io/log.hpp"

namespace symoro::io {

// The family of the held-out runs (a split's held-out part, the twin's V01-V03): identify's and
// the diagnosis's default held-out set.
inline constexpr const char* kHeldOutFamily = "V";

struct DatasetRun {
  std::string trajectory, family;
  int trial = 1;
  std::filesystem::path file;  // absolute when read; when written, absolute or relative to the folder
  // The rows of the file this run is: window_start <= t < window_end (s, log time). Two runs
  // may share a file: a long run split into a fitting part and a held-out part.
  double window_start = -std::numeric_limits<double>::infinity();
  double window_end = std::numeric_limits<double>::infinity();
};

// How the twin made a dataset (dynid twin dataset): records, not inputs of any command.
struct TwinDatasetRecord {
  std::uint64_t seed = 0;
  int trials = 0;
  std::vector<std::string> effects;  // the effects switched on
};

// What an import read and wrote (dynid import), in total and per log.
struct ImportCounts {
  int inputs = 0, rows = 0, written = 0, stale_rows = 0, duplicate_rows = 0;
};
struct ImportedFile {
  std::string file;  // relative to the dataset folder
  int rows = 0, stale_rows = 0, duplicate_rows = 0;
  double sample_time = 0;
  std::string velocity;  // "measured" or "differentiated"
};

struct Dataset {
  std::filesystem::path dir;
  std::string robot;
  std::string twin;            // the twin configuration that made it ("" for measured data)
  std::string twin_overrides;  // the overrides it was made with, a file in the folder (absolute
                               // when read; when written, absolute or relative to the folder), or ""
  std::string source;          // "imported" (dynid import), or "" (not recorded)
  int robot_line = 0;          // line of "robot:" in dataset.yaml (0: none; set when read)
  std::optional<TwinDatasetRecord> twin_record;
  double split = 0;  // dynid import --split (a record; the windows are what counts)
  std::optional<ImportCounts> import;
  std::vector<ImportedFile> imported;
  std::vector<DatasetRun> runs;
  // The run of a trajectory and trial; throws DataError naming dataset.yaml when absent.
  const DatasetRun& find(const std::string& trajectory, int trial) const;
};

// Throws DataError (file and line) on a missing or malformed manifest or a listed file that
// does not exist.
Dataset read_dataset(const std::filesystem::path& dir);

// Writes <dataset.dir>/dataset.yaml atomically (write it last: it lists files already in
// place). Strings are quoted, numbers in their shortest round-trip form, so that read_dataset
// gives back what was written.
void write_dataset(const Dataset& dataset);

// The run's log restricted to its window (time stamps kept as logged; meta.trajectory is the
// run's name, so that later errors name the run). DataError if the window is empty.
Log read_run_log(const DatasetRun& run);

// The same, checked against the model it is for: the log's robot (when its sidecar names one)
// and its joint count. DataError naming the log (its sidecar for the robot) otherwise.
Log read_run_log(const DatasetRun& run, const std::string& robot, int joints);

// DataError(dataset.yaml, line of robot:) when the dataset was made for another robot. A
// dataset that names no robot passes.
void check_dataset_robot(const Dataset& dataset, const std::string& robot);
// A log read alone (its file `csv`) is of `robot` (its sidecar says) and has `joints` joints;
// DataError naming the sidecar or the file otherwise (a UR5 model on an RX-90 log printed an
// RMSE of 77 N m and exited 0).
void check_log_robot(const Log& log, const std::filesystem::path& csv, const std::string& robot, int joints);

// The logs a command's input names, checked as above: every run of `trial` of a dataset folder
// (named by its trajectory), or one log file (named by its stem). Empty when the dataset has no
// run of that trial: the caller says what to give instead.
struct NamedLog {
  std::string name;
  Log log;
};
std::vector<NamedLog> read_input_logs(const std::filesystem::path& input, const std::string& robot, int joints,
                                      int trial);

}  // namespace symoro::io
