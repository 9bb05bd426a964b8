// dynid twin's bodies for one robot (included by the generated units only): one run, a whole
// dataset (twin/dataset.hpp makes it), and the speed measurement.
#pragma once

#include <algorithm>
#include <optional>

#include <fmt/format.h>

#include "dynid_twin.hpp"
#include "symoro/io/log.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/dataset.hpp"
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
  const auto file = std::filesystem::path(o.out) / twin::run_file_name(o.trajectory, o.trial);
  io::write_log(file, log);
  fmt::print("{}: {} rows; {}\n", file.string(), log.samples(), twin::describe_run(stats));
  fmt::print("max |q_ref - q| per joint (deg):");
  for (int j = 0; j < Model::nq; ++j) fmt::print(" {:.3f}", stats.max_error(j) * 180 / 3.14159265358979323846);
  fmt::print("\nmax |torque| per joint (N m):");
  for (int j = 0; j < Model::nq; ++j) fmt::print(" {:.3f}", stats.max_torque(j));
  fmt::print("\n");
}

template <class Model>
void twin_dataset(const Common& common, const TwinOptions& o) {
  const twin::ClosedLoopTwin<Model> sim(load_config<Model>(common, o));
  const auto design = read_design(common, joint_list<Model>());
  std::vector<trajectory::Trajectory> trajs;
  for (const auto& n : o.only.empty() ? design.names() : o.only) trajs.push_back(design.build(n));
  twin::TwinDatasetOptions d;
  d.out = o.out;
  d.robot = common.robot;
  d.seed = o.seed;
  d.trials = o.trials;
  d.workers = o.jobs;
  d.overrides = o.config;
  std::optional<Progress> progress;
  d.on_start = [&](int to_run, int skipped) {
    if (skipped > 0) fmt::print(stderr, "{} runs already finished in {} (same seed and twin): skipped\n", skipped, o.out);
    progress.emplace(to_run, "twin");
  };
  d.on_run = [&](const std::string& run, const std::string& what) { progress->done(run, what); };
  const twin::TwinDatasetSummary s = twin::make_twin_dataset(sim, trajs, d);
  if (!s.coordinator) return;
  fmt::print("{} runs ({} new, {} skipped) in {}: {:.0f} s simulated in {:.1f} s wall on {}{} workers\n", s.runs, s.made,
             s.skipped, o.out, s.simulated, s.wall, s.ranks > 1 ? fmt::format("{} ranks x ", s.ranks) : "", s.workers);
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
