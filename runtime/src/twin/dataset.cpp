#include "symoro/twin/dataset.hpp"

#include <algorithm>
#include <chrono>
#include <sstream>

#include <fmt/format.h>

#include "symoro/io/atomic_file.hpp"
#include "symoro/io/dataset.hpp"
#include "symoro/io/text_file.hpp"
#include "symoro/parallel/farm.hpp"

namespace symoro::twin {

namespace {

// A finished run is one whose sidecar (written last) names the same seed, trial and twin
// (configuration fingerprint and effects).
bool finished(const std::filesystem::path& csv, std::uint64_t seed, int trial, const std::string& notes) {
  if (!std::filesystem::exists(io::metadata_path(csv)) || !std::filesystem::exists(csv)) return false;
  try {
    const io::LogMetadata m = io::read_log_metadata(csv);
    return m.seed == seed && m.trial == trial && m.notes == notes;
  } catch (const std::exception&) {
    return false;  // unreadable: run it again
  }
}

}  // namespace

std::string run_file_name(const std::string& trajectory, int trial) {
  return fmt::format("{}_t{}.csv", trajectory, trial);
}

std::string describe_run(const RunStats& s) {
  return fmt::format("{:.1f} s simulated in {:.2f} s ({:.0f}x), max |error| {:.2f} deg, {} dropped, {} saturated",
                     s.simulated, s.wall, s.simulated / std::max(s.wall, 1e-9),
                     s.max_error.maxCoeff() * 180 / 3.14159265358979323846, s.dropped, s.saturated);
}

TwinDatasetSummary make_twin_dataset(const ClosedLoopTwin& twin,
                                     const std::vector<trajectory::Trajectory>& trajectories,
                                     const TwinDatasetOptions& options) {
  return make_twin_dataset(
      [&twin](const trajectory::Trajectory& t, const RunOptions& ro, RunStats* st) { return twin.run(t, ro, st); },
      twin.notes(), twin.config(), trajectories, options);
}

TwinDatasetSummary make_twin_dataset(const RunTwin& run, const std::string& notes, const TwinConfig& config,
                                     const std::vector<trajectory::Trajectory>& trajs,
                                     const TwinDatasetOptions& options) {
  std::filesystem::create_directories(options.out);
  TwinDatasetSummary summary;
  summary.runs = static_cast<int>(trajs.size()) * options.trials;

  struct Job {
    int traj, trial;
  };
  std::vector<Job> jobs;
  for (int t = 0; t < static_cast<int>(trajs.size()); ++t)
    for (int k = 1; k <= options.trials; ++k) {
      const auto file = options.out / run_file_name(trajs[t].name, k);
      if (finished(file, run_seed(options.seed, trajs[t].name, k), k, notes))
        ++summary.skipped;
      else
        jobs.push_back({t, k});
    }
  summary.made = static_cast<int>(jobs.size());
  // Longest runs first: better load balance across workers.
  std::stable_sort(jobs.begin(), jobs.end(),
                   [&](const Job& a, const Job& b) { return trajs[a.traj].duration() > trajs[b.traj].duration(); });
  summary.coordinator = parallel::place().coordinator();
  if (summary.coordinator && options.on_start) options.on_start(summary.made, summary.skipped);
  auto name_of = [&](const Job& j) { return fmt::format("{} t{}", trajs[j.traj].name, j.trial); };

  // Each worker writes its run's log (atomically, a file of its own) and sends rank 0 what it
  // simulated.
  std::vector<std::string> tasks;
  for (const Job& j : jobs) tasks.push_back(fmt::format("{} {}", j.traj, j.trial));
  std::string errors;
  parallel::Farm farm;
  farm.work = [&](const std::string& task, const std::function<void(const std::string&)>& emit) {
    std::istringstream in(task);
    Job j{};
    in >> j.traj >> j.trial;
    RunOptions ro;
    ro.robot = options.robot;
    ro.trial = j.trial;
    ro.seed = run_seed(options.seed, trajs[j.traj].name, j.trial);
    RunStats st;
    const io::Log log = run(trajs[j.traj], ro, &st);
    io::write_log(options.out / run_file_name(trajs[j.traj].name, j.trial), log);
    emit(fmt::format("{:.17g} {}", st.simulated, describe_run(st)));
  };
  farm.on_result = [&](std::size_t i, const std::string& text) {
    std::istringstream in(text);
    double s = 0;
    in >> s;
    summary.simulated += s;
    std::string rest;
    std::getline(in, rest);
    if (options.on_run) options.on_run(name_of(jobs[i]), rest.empty() ? rest : rest.substr(1));
  };
  farm.on_end = [&](const parallel::TaskEnd& e) {
    if (e.failed) errors += fmt::format("{}{}: {}", errors.empty() ? "" : "; ", name_of(jobs[e.task]), e.failure);
  };
  parallel::FarmOptions fo;
  fo.workers = options.workers;
  const auto t0 = std::chrono::steady_clock::now();
  const parallel::FarmSummary farmed = parallel::run_farm(tasks, farm, fo);
  summary.ranks = farmed.ranks;
  summary.workers = farmed.workers;
  if (!summary.coordinator) return summary;
  if (!errors.empty()) throw std::runtime_error("twin dataset: failed runs (the others are written): " + errors);
  summary.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  io::Dataset d;
  d.dir = options.out;
  d.robot = options.robot;
  d.twin = config.path;
  if (!options.overrides.empty()) {
    d.twin_overrides = "twin_overrides.yaml";  // relative to the folder
    io::write_file_atomically(options.out / d.twin_overrides, io::read_text_file(options.overrides));
  }
  d.twin_record = io::TwinDatasetRecord{options.seed, options.trials, config.effects.enabled()};
  for (const trajectory::Trajectory& t : trajs)
    for (int k = 1; k <= options.trials; ++k) d.runs.push_back({t.name, t.family, k, run_file_name(t.name, k)});
  io::write_dataset(d);
  return summary;
}

}  // namespace symoro::twin
