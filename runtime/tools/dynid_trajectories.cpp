// dynid trajectories: list the robot's designed identification trajectories or write them as
// reference files (time, q_ref, qd_ref, qdd_ref at the control period).
#include <CLI/CLI.hpp>

#include "dynid_trajectories.hpp"
#include "dynid_numbers.hpp"

namespace symoro::dynid {

void add_trajectory_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<TrajectoryOptions>();
  auto* cmd = app.add_subcommand("trajectories", "List the identification trajectories, or write them as reference files");
  cmd->add_option("--robot", common.robot, "Robot folder name under robots/")->required();
  cmd->add_option("--robots-dir", common.robots_dir, "Where the robot folders are");
  cmd->add_option("-o,--output", o->out, "Write <name>.csv and <name>.meta.yaml here (default: list only)");
  cmd->add_option("--only", o->only, "Only these trajectories");
  cmd->add_option("--period", o->period, "Sample period of the reference files, s")->check(numbers::positive(10, "> 0 and <= 10 s"));
  cmd->callback([&common, o] { trajectories_units().robot(common)(common, *o); });
}

}  // namespace symoro::dynid
