// A dataset from the digital twin (dynid twin dataset): every trajectory for several trials,
// each run's seed drawn from one dataset seed, on the farm (threads, or MPI ranks), resumable:
// a run whose log's sidecar names the same seed, trial and twin is not run again. The logs are
// written as they finish, the manifest (io/dataset.hpp) last.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "symoro/io/log.hpp"
#include "symoro/trajectory/trajectory.hpp"
#include "symoro/twin/simulator.hpp"

namespace symoro::twin {

struct TwinDatasetOptions {
  std::filesystem::path out;  // the dataset folder (created)
  std::string robot;
  std::uint64_t seed = 1;  // the dataset's seed (run_seed derives each run's)
  int trials = 3;
  int workers = 0;                  // per rank, as parallel::FarmOptions::workers
  std::filesystem::path overrides;  // the twin.yaml overrides the twin was made with, or "":
                                    // copied into the folder, so the truth travels with the data
  // On the coordinator: before the runs (how many will run, how many are finished already), and
  // after each ("AG02 t2", describe_run's text).
  std::function<void(int to_run, int skipped)> on_start;
  std::function<void(const std::string& run, const std::string& what)> on_run;
};

struct TwinDatasetSummary {
  bool coordinator = true;  // false on the other MPI ranks (nothing else is set there)
  int runs = 0, made = 0, skipped = 0;
  double simulated = 0, wall = 0;  // s of motion simulated by this call; s it took
  int ranks = 1, workers = 1;
};

// One closed-loop run of a twin (ClosedLoopTwin::run).
using RunTwin = std::function<io::Log(const trajectory::Trajectory&, const RunOptions&, RunStats*)>;

// The runs and the manifest. `notes` and `config` are the twin's (ClosedLoopTwin::notes and
// ::config). Throws std::runtime_error naming the failed runs, after the others are written (a
// rerun does only the failed ones); the manifest is then not written.
TwinDatasetSummary make_twin_dataset(const RunTwin& run, const std::string& notes, const TwinConfig& config,
                                     const std::vector<trajectory::Trajectory>& trajectories,
                                     const TwinDatasetOptions& options);

// The same with the twin's own runs.
TwinDatasetSummary make_twin_dataset(const ClosedLoopTwin& twin,
                                     const std::vector<trajectory::Trajectory>& trajectories,
                                     const TwinDatasetOptions& options);

// A run's log file in a dataset: <trajectory>_t<trial>.csv.
std::string run_file_name(const std::string& trajectory, int trial);

// "12.0 s simulated in 0.31 s (39x), max |error| 0.42 deg, 0 dropped, 0 saturated".
std::string describe_run(const RunStats& s);

}  // namespace symoro::twin
