// dynid twin's bodies for one robot (included by the generated units only): one run, a whole
// dataset (resumable, parallel), and the speed measurement.
#pragma once

#include <algorithm>
#include <chrono>
#include <fstream>
#include <optional>
#include <sstream>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "dynid_twin.hpp"
#include "symoro/io/atomic_file.hpp"
#include "symoro/io/log.hpp"
#include "symoro/parallel/farm.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/simulator.hpp"

namespace symoro::dynid {

namespace twin_detail {

template <class Model>
twin::TwinConfig load_config(const Common& common, const TwinOptions& o) {
  const auto path = common.robot_dir() / "twin.yaml";
  if (!std::filesystem::exists(path))
    throw UsageError(fmt::format("robot '{}' has no digital twin ({} not found)", common.robot, path.string()));
  twin::TwinConfig c = twin::read_twin_config(path, Model::nq, o.config);
  try {
    if (o.ideal) c.effects.disable_all();
    for (const auto& e : o.effects) c.effects.set(e, true);
    for (const auto& e : o.without) c.effects.set(e, false);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  return c;
}

inline std::string run_file(const std::string& trajectory, int trial) { return fmt::format("{}_t{}.csv", trajectory, trial); }

inline std::string describe(const twin::RunStats& s) {
  return fmt::format("{:.1f} s simulated in {:.2f} s ({:.0f}x), max |error| {:.2f} deg, {} dropped, {} saturated",
                     s.simulated, s.wall, s.simulated / std::max(s.wall, 1e-9),
                     s.max_error.maxCoeff() * 180 / 3.14159265358979323846, s.dropped, s.saturated);
}

inline trajectory::TrajectoryDesign read_design(const Common& common, const std::vector<JointInfo>& joints) {
  return trajectory::TrajectoryDesign::read(common.design_path(), joints);
}

template <class Model>
void twin_run(const Common& common, const TwinOptions& o) {
  const twin::ClosedLoopTwin<Model> sim(load_config<Model>(common, o));
  const auto traj = read_design(common, joint_list<Model>()).build(o.trajectory);
  twin::RunOptions ro;
  ro.robot = common.robot;
  ro.trial = o.trial;
  ro.seed = twin::run_seed(o.seed, o.trajectory, o.trial);
  twin::RunStats stats;
  const io::Log log = sim.run(traj, ro, &stats);
  std::filesystem::create_directories(o.out);
  const auto file = std::filesystem::path(o.out) / run_file(o.trajectory, o.trial);
  io::write_log(file, log);
  fmt::print("{}: {} rows; {}\n", file.string(), log.samples(), describe(stats));
  fmt::print("max |q_ref - q| per joint (deg):");
  for (int j = 0; j < Model::nq; ++j) fmt::print(" {:.3f}", stats.max_error(j) * 180 / 3.14159265358979323846);
  fmt::print("\nmax |torque| per joint (N m):");
  for (int j = 0; j < Model::nq; ++j) fmt::print(" {:.3f}", stats.max_torque(j));
  fmt::print("\n");
}

// A finished run is one whose sidecar (written last) names the same seed, trial and twin
// (configuration fingerprint and effects).
inline bool finished(const std::filesystem::path& csv, std::uint64_t seed, int trial, const std::string& notes) {
  const auto meta = io::metadata_path(csv);
  if (!std::filesystem::exists(meta) || !std::filesystem::exists(csv)) return false;
  try {
    const YAML::Node m = YAML::LoadFile(meta.string());
    return m["seed"].as<std::uint64_t>() == seed && m["trial"].as<int>() == trial &&
           m["notes"].as<std::string>() == notes;
  } catch (const YAML::Exception&) {
    return false;
  }
}

template <class Model>
void twin_dataset(const Common& common, const TwinOptions& o) {
  const twin::ClosedLoopTwin<Model> sim(load_config<Model>(common, o));
  const auto design = read_design(common, joint_list<Model>());
  const std::vector<std::string> names = o.only.empty() ? design.names() : o.only;
  std::vector<trajectory::Trajectory> trajs;
  for (const auto& n : names) trajs.push_back(design.build(n));
  std::filesystem::create_directories(o.out);

  struct Job { int traj, trial; };
  std::vector<Job> jobs;
  int skipped = 0;
  for (int t = 0; t < static_cast<int>(trajs.size()); ++t)
    for (int k = 1; k <= o.trials; ++k) {
      const auto file = std::filesystem::path(o.out) / run_file(names[t], k);
      if (finished(file, twin::run_seed(o.seed, names[t], k), k, sim.notes())) ++skipped;
      else jobs.push_back({t, k});
    }
  // Longest runs first: better load balance across workers.
  std::stable_sort(jobs.begin(), jobs.end(), [&](const Job& a, const Job& b) { return trajs[a.traj].duration() > trajs[b.traj].duration(); });
  if (skipped > 0 && parallel::place().coordinator()) fmt::print(stderr, "{} runs already finished in {} (same seed and twin): skipped\n", skipped, o.out);

  // The runs on the farm (threads here, or MPI ranks under mpirun): each worker writes its run's
  // log (atomically, a file of its own) and sends rank 0 what it simulated.
  std::vector<std::string> tasks;
  for (const Job& j : jobs) tasks.push_back(fmt::format("{} {}", j.traj, j.trial));
  const bool coordinator = parallel::place().coordinator();
  std::optional<Progress> progress;
  if (coordinator) progress.emplace(static_cast<int>(jobs.size()), "twin");
  std::string errors;
  double simulated = 0;
  parallel::Farm farm;
  farm.work = [&](const std::string& task, const std::function<void(const std::string&)>& emit) {
    std::istringstream in(task);
    Job j{};
    in >> j.traj >> j.trial;
    twin::RunOptions ro;
    ro.robot = common.robot;
    ro.trial = j.trial;
    ro.seed = twin::run_seed(o.seed, names[j.traj], j.trial);
    twin::RunStats st;
    const io::Log log = sim.run(trajs[j.traj], ro, &st);
    io::write_log(std::filesystem::path(o.out) / run_file(names[j.traj], j.trial), log);
    emit(fmt::format("{:.17g} {}", st.simulated, describe(st)));
  };
  farm.on_result = [&](std::size_t i, const std::string& text) {
    std::istringstream in(text);
    double s = 0;
    in >> s;
    simulated += s;
    std::string rest;
    std::getline(in, rest);
    progress->done(fmt::format("{} t{}", names[jobs[i].traj], jobs[i].trial), rest.empty() ? rest : rest.substr(1));
  };
  farm.on_end = [&](const parallel::TaskEnd& e) {
    if (e.failed) errors += fmt::format("{}{} t{}: {}", errors.empty() ? "" : "; ", names[jobs[e.task].traj], jobs[e.task].trial, e.failure);
  };
  parallel::FarmOptions fo;
  fo.workers = o.jobs;
  const auto t0 = std::chrono::steady_clock::now();
  const parallel::FarmSummary farmed = parallel::run_farm(tasks, farm, fo);
  if (!coordinator) return;
  // The finished runs stay on disk: a rerun does only the failed ones.
  if (!errors.empty()) throw std::runtime_error("twin dataset: failed runs (the others are written): " + errors);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // The manifest: what the dataset holds and how it was made (written last, atomically).
  YAML::Emitter y;
  y << YAML::BeginMap << YAML::Key << "format" << YAML::Value << "symoro-dataset 1";
  y << YAML::Key << "robot" << YAML::Value << common.robot << YAML::Key << "seed" << YAML::Value << o.seed;
  y << YAML::Key << "trials" << YAML::Value << o.trials;
  y << YAML::Key << "twin" << YAML::Value << sim.config().path;
  if (!o.config.empty()) {
    // The overrides travel with the dataset: its truth (hidden effects) stays known.
    std::ifstream in(o.config);
    std::stringstream text;
    text << in.rdbuf();
    io::write_file_atomically(std::filesystem::path(o.out) / "twin_overrides.yaml", text.str());
    y << YAML::Key << "twin_overrides" << YAML::Value << "twin_overrides.yaml";
  }
  y << YAML::Key << "effects" << YAML::Value << YAML::Flow << sim.config().effects.enabled();
  y << YAML::Key << "runs" << YAML::Value << YAML::BeginSeq;
  for (int t = 0; t < static_cast<int>(trajs.size()); ++t)
    for (int k = 1; k <= o.trials; ++k)
      y << YAML::Flow << YAML::BeginMap << YAML::Key << "trajectory" << YAML::Value << names[t] << YAML::Key << "family"
        << YAML::Value << trajs[t].family << YAML::Key << "trial" << YAML::Value << k << YAML::Key << "file"
        << YAML::Value << run_file(names[t], k) << YAML::EndMap;
  y << YAML::EndSeq << YAML::EndMap;
  io::write_file_atomically(std::filesystem::path(o.out) / "dataset.yaml", std::string(y.c_str()) + "\n");
  fmt::print("{} runs ({} new, {} skipped) in {}: {:.0f} s simulated in {:.1f} s wall on {}{} workers\n",
             trajs.size() * o.trials, jobs.size(), skipped, o.out, simulated, wall,
             farmed.ranks > 1 ? fmt::format("{} ranks x ", farmed.ranks) : "", farmed.workers);
}

template <class Model>
void twin_bench(const Common& common, const TwinOptions& o) {
  const twin::ClosedLoopTwin<Model> sim(load_config<Model>(common, o));
  const auto traj = read_design(common, joint_list<Model>()).build(o.trajectory);
  twin::RunOptions ro;
  ro.robot = common.robot;
  double best = 0, total_sim = 0, total_wall = 0;
  int runs = 0;
  while (total_wall < o.repeat_seconds || runs < 2) {
    ro.seed = twin::run_seed(o.seed, o.trajectory, ++runs);
    twin::RunStats st;
    sim.run(traj, ro, &st);
    total_sim += st.simulated;
    total_wall += st.wall;
    best = std::max(best, st.simulated / st.wall);
  }
  fmt::print("twin {} on {} ({:.1f} s), one core, effects: {}\n", common.robot, o.trajectory, traj.duration(),
             fmt::join(sim.config().effects.enabled(), ", "));
  fmt::print("{} runs: {:.0f} simulated s per wall s on average, {:.0f} best ({:.2f} us per 1 ms control cycle)\n", runs,
             total_sim / total_wall, best, 1e3 / (total_sim / total_wall));
}

}  // namespace twin_detail

template <class Full, class Model>
void TwinCommand::run(const Common& common, const TwinOptions& o) {
  switch (o.mode) {
    case TwinOptions::Mode::run: return twin_detail::twin_run<Full>(common, o);
    case TwinOptions::Mode::dataset: return twin_detail::twin_dataset<Full>(common, o);
    case TwinOptions::Mode::bench: return twin_detail::twin_bench<Full>(common, o);
  }
}

}  // namespace symoro::dynid
