// A dataset folder (dynid twin dataset, or logs of the real arm with the same layout): its
// manifest dataset.yaml lists every run's trajectory, family, trial and CSV file.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace symoro::identify {

struct DatasetRun {
  std::string trajectory, family;
  int trial = 1;
  std::filesystem::path file;  // absolute
};

struct Dataset {
  std::filesystem::path dir;
  std::string robot;
  std::string twin;             // the twin configuration that made it ("" for measured data)
  std::string twin_overrides;   // the overrides it was made with (dynid twin dataset --config), or ""
  std::vector<DatasetRun> runs;
  // The run of a trajectory and trial; throws DataError naming dataset.yaml when absent.
  const DatasetRun& find(const std::string& trajectory, int trial) const;
};

// Throws DataError (file and line) on a missing or malformed manifest or a listed file that
// does not exist.
Dataset read_dataset(const std::filesystem::path& dir);

}  // namespace symoro::identify
