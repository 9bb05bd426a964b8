// dynid twin: run the digital twin on one trajectory, produce a whole dataset (every designed
// trajectory, repeated trials, one seed; resumable and parallel), or measure its speed.
#include <algorithm>
#include <optional>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "dynid_numbers.hpp"
#include "dynid_robots.hpp"
#include "dynid_twin.hpp"
#include "symoro/io/log.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/dataset.hpp"
#include "symoro/twin/simulator.hpp"

namespace symoro::dynid {

namespace {

twin::TwinConfig load_config(const Common& common, const TwinOptions& options, int joints) {
  const auto path = common.robot_dir() / "twin.yaml";
  if (!std::filesystem::exists(path))
    throw UsageError(fmt::format("robot '{}' has no digital twin ({} not found)", common.robot, path.string()));
  twin::TwinConfig c = twin::read_twin_config(path, joints, options.config);
  try {
    if (options.ideal) c.effects.disable_all();
    for (const auto& e : options.effects) c.effects.set(e, true);
    for (const auto& e : options.without) c.effects.set(e, false);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  return c;
}

// The robot's twin: its full model's plant, twin.yaml with the command's overrides.
twin::ClosedLoopTwin make_twin(const Common& common, const TwinOptions& options) {
  robot::ModelHandle full = full_model(common);
  twin::TwinConfig c = load_config(common, options, full.nq());
  return twin::ClosedLoopTwin(std::move(full), std::move(c));
}

void twin_run(const Common& common, const TwinOptions& options) {
  const twin::ClosedLoopTwin sim = make_twin(common, options);
  const auto traj = read_design(common, sim.model().joints()).build(options.trajectory);
  twin::RunOptions ro;
  ro.robot = common.robot;
  ro.trial = options.trial;
  ro.seed = twin::run_seed(options.seed, options.trajectory, options.trial);
  twin::RunStats stats;
  const io::Log log = sim.run(traj, ro, &stats);
  std::filesystem::create_directories(options.out);
  const auto file = std::filesystem::path(options.out) / twin::run_file_name(options.trajectory, options.trial);
  io::write_log(file, log);
  fmt::print("{}: {} rows; {}\n", file.string(), log.samples(), twin::describe_run(stats));
  fmt::print("max |q_ref - q| per joint (deg):");
  for (int j = 0; j < sim.joints(); ++j) fmt::print(" {:.3f}", stats.max_error(j) * 180 / 3.14159265358979323846);
  fmt::print("\nmax |torque| per joint (N m):");
  for (int j = 0; j < sim.joints(); ++j) fmt::print(" {:.3f}", stats.max_torque(j));
  fmt::print("\n");
}

void twin_dataset(const Common& common, const TwinOptions& options) {
  const twin::ClosedLoopTwin sim = make_twin(common, options);
  const auto design = read_design(common, sim.model().joints());
  std::vector<trajectory::Trajectory> trajs;
  for (const auto& n : options.only.empty() ? design.names() : options.only) trajs.push_back(design.build(n));
  twin::TwinDatasetOptions d;
  d.out = options.out;
  d.robot = common.robot;
  d.seed = options.seed;
  d.trials = options.trials;
  d.workers = options.jobs;
  d.overrides = options.config;
  std::optional<Progress> progress;
  d.on_start = [&](int to_run, int skipped) {
    if (skipped > 0)
      fmt::print(stderr, "{} runs already finished in {} (same seed and twin): skipped\n", skipped, options.out);
    progress.emplace(to_run, "twin");
  };
  d.on_run = [&](const std::string& run, const std::string& what) { progress->done(run, what); };
  const twin::TwinDatasetSummary s = twin::make_twin_dataset(sim, trajs, d);
  if (!s.coordinator) return;
  fmt::print("{} runs ({} new, {} skipped) in {}: {:.0f} s simulated in {:.1f} s wall on {}{} workers\n", s.runs,
             s.made, s.skipped, options.out, s.simulated, s.wall,
             s.ranks > 1 ? fmt::format("{} ranks x ", s.ranks) : "", s.workers);
}

void twin_bench(const Common& common, const TwinOptions& options) {
  const twin::ClosedLoopTwin sim = make_twin(common, options);
  const auto traj = read_design(common, sim.model().joints()).build(options.trajectory);
  twin::RunOptions ro;
  ro.robot = common.robot;
  double best = 0, total_sim = 0, total_wall = 0;
  int runs = 0;
  while (total_wall < options.repeat_seconds || runs < 2) {
    ro.seed = twin::run_seed(options.seed, options.trajectory, ++runs);
    twin::RunStats st;
    sim.run(traj, ro, &st);
    total_sim += st.simulated;
    total_wall += st.wall;
    best = std::max(best, st.simulated / st.wall);
  }
  fmt::print("twin {} on {} ({:.1f} s), one core, effects: {}\n", common.robot, options.trajectory, traj.duration(),
             fmt::join(sim.config().effects.enabled(), ", "));
  fmt::print("{} runs: {:.0f} simulated s per wall s on average, {:.0f} best ({:.2f} us per 1 ms control cycle)\n",
             runs, total_sim / total_wall, best, 1e3 / (total_sim / total_wall));
}

void add_config_options(CLI::App* cmd, Common& common, TwinOptions& options) {
  add_robot_options(cmd, common);
  cmd->add_option("--design", common.design,
                  "A trajectory design file (e.g. dynid excite's) instead of robots/<robot>/trajectories.yaml")
      ->check(CLI::ExistingFile);
  cmd->add_option("--config", options.config, "A YAML file overriding parts of robots/<robot>/twin.yaml")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--ideal", options.ideal, "Turn every effect off (quantization and delay remain)");
  cmd->add_option("--effects", options.effects,
                  "Turn these effects on (coulomb, stribeck, torque_offset, backlash, payload, "
                  "torque_constant_error, actuation_delay, sensor_noise, timestamp_jitter, dropped_samples)")
      ->delimiter(',');
  cmd->add_option("--without", options.without, "Turn these effects off")->delimiter(',');
}

}  // namespace

void run_twin(const Common& common, const TwinOptions& options) {
  switch (options.mode) {
    case TwinOptions::Mode::run:
      return twin_run(common, options);
    case TwinOptions::Mode::dataset:
      return twin_dataset(common, options);
    case TwinOptions::Mode::bench:
      return twin_bench(common, options);
  }
}

void add_twin_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<TwinOptions>();
  auto* twin = app.add_subcommand("twin", "The digital twin: closed-loop simulation of the arm and its servos");
  twin->require_subcommand(1);

  auto* run = twin->add_subcommand("run", "Run one trajectory and write its log");
  add_config_options(run, common, *o);
  run->add_option("--trajectory", o->trajectory, "Trajectory name (see dynid trajectories)")->required();
  run->add_option("-o,--output", o->out, "Output directory")->required();
  run->add_option("--trial", o->trial, "Trial number")->check(numbers::count(1, 1e6));
  run->add_option("--seed", o->seed, "Dataset seed (the run's seed derives from it, the trajectory and the trial)")
      ->check(numbers::seed());
  run->callback([&common, o] {
    o->mode = TwinOptions::Mode::run;
    run_twin(common, *o);
  });

  auto* data = twin->add_subcommand("dataset", "Run every trajectory for several trials (resumable, parallel)");
  add_config_options(data, common, *o);
  data->add_option("-o,--output", o->out, "Output directory")->required();
  data->add_option("--trials", o->trials, "Repeated trials per trajectory")
      ->check(numbers::count(1, 1e4))
      ->capture_default_str();
  data->add_option("--seed", o->seed, "Dataset seed")->check(numbers::seed())->capture_default_str();
  data->add_option("--jobs", o->jobs,
                   "Worker threads per rank (default: the cores, shared among the MPI ranks on a machine)")
      ->check(numbers::count(1, 1024));
  data->add_option("--only", o->only, "Only these trajectories");
  data->callback([&common, o] {
    o->mode = TwinOptions::Mode::dataset;
    run_twin(common, *o);
  });

  auto* bench = twin->add_subcommand("bench", "Simulated seconds per wall second on one core");
  add_config_options(bench, common, *o);
  bench->add_option("--trajectory", o->trajectory, "Trajectory to simulate (default AG02)");
  bench->add_option("--seconds", o->repeat_seconds, "Measure for at least this long")
      ->check(numbers::positive(3600, "> 0 and <= 3600 s"));
  bench->callback([&common, o] {
    o->mode = TwinOptions::Mode::bench;
    run_twin(common, *o);
  });
}

}  // namespace symoro::dynid
