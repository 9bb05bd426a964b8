// dynid twin: run the digital twin on one trajectory, produce a whole dataset (every designed
// trajectory, repeated trials, one seed; resumable and parallel), or measure its speed.
#include <CLI/CLI.hpp>

#include "dynid_twin.hpp"
#include "dynid_numbers.hpp"

namespace symoro::dynid {

namespace {

void add_config_options(CLI::App* cmd, Common& common, TwinOptions& o) {
  add_robot_options(cmd, common);
  cmd->add_option("--design", common.design, "A trajectory design file (e.g. dynid excite's) instead of robots/<robot>/trajectories.yaml")
      ->check(CLI::ExistingFile);
  cmd->add_option("--config", o.config, "A YAML file overriding parts of robots/<robot>/twin.yaml")->check(CLI::ExistingFile);
  cmd->add_flag("--ideal", o.ideal, "Turn every effect off (quantization and delay remain)");
  cmd->add_option("--effects", o.effects, "Turn these effects on (coulomb, stribeck, torque_offset, backlash, payload, "
                                           "torque_constant_error, actuation_delay, sensor_noise, timestamp_jitter, dropped_samples)")
      ->delimiter(',');
  cmd->add_option("--without", o.without, "Turn these effects off")->delimiter(',');
}

}  // namespace

void add_twin_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<TwinOptions>();
  auto* twin = app.add_subcommand("twin", "The digital twin: closed-loop simulation of the arm and its servos");
  twin->require_subcommand(1);

  auto* run = twin->add_subcommand("run", "Run one trajectory and write its log");
  add_config_options(run, common, *o);
  run->add_option("--trajectory", o->trajectory, "Trajectory name (see dynid trajectories)")->required();
  run->add_option("-o,--output", o->out, "Output directory")->required();
  run->add_option("--trial", o->trial, "Trial number")->check(numbers::count(1, 1e6));
  run->add_option("--seed", o->seed, "Dataset seed (the run's seed derives from it, the trajectory and the trial)");
  run->callback([&common, o] {
    o->mode = TwinOptions::Mode::run;
    twin_units().robot(common)(common, *o);
  });

  auto* data = twin->add_subcommand("dataset", "Run every trajectory for several trials (resumable, parallel)");
  add_config_options(data, common, *o);
  data->add_option("-o,--output", o->out, "Output directory")->required();
  data->add_option("--trials", o->trials, "Repeated trials per trajectory")->check(numbers::count(1, 1e4));
  data->add_option("--seed", o->seed, "Dataset seed");
  data->add_option("--jobs", o->jobs, "Worker threads per rank (default: the cores, shared among the MPI ranks on a machine)")->check(numbers::count(1, 1024));
  data->add_option("--only", o->only, "Only these trajectories");
  data->callback([&common, o] {
    o->mode = TwinOptions::Mode::dataset;
    twin_units().robot(common)(common, *o);
  });

  auto* bench = twin->add_subcommand("bench", "Simulated seconds per wall second on one core");
  add_config_options(bench, common, *o);
  bench->add_option("--trajectory", o->trajectory, "Trajectory to simulate (default AG02)");
  bench->add_option("--seconds", o->repeat_seconds, "Measure for at least this long")->check(numbers::positive(3600, "> 0 and <= 3600 s"));
  bench->callback([&common, o] {
    o->mode = TwinOptions::Mode::bench;
    twin_units().robot(common)(common, *o);
  });
}

}  // namespace symoro::dynid
