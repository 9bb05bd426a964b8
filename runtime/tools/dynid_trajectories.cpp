// dynid trajectories: list the robot's designed identification trajectories or write them as
// reference files (time, q_ref, qd_ref, qdd_ref at the control period).
#include <fmt/format.h>

#include "dynid_common.hpp"
#include "symoro/io/log.hpp"
#include "symoro/robots_registry.hpp"
#include "symoro/trajectory/design.hpp"

namespace symoro::dynid {

namespace {

struct TrajectoryOptions {
  std::string out;
  std::vector<std::string> only;
  double period = 0.001;
};

template <class Model>
void run_trajectories(const Common& common, const TrajectoryOptions& o) {
  const auto design = trajectory::TrajectoryDesign::read(common.robot_dir() / "trajectories.yaml", joint_list<Model>());
  const std::vector<std::string> names = o.only.empty() ? design.names() : o.only;
  std::vector<std::string> joint_names;
  for (const auto& j : Model::joints) joint_names.push_back(j.name);
  if (o.out.empty()) {
    fmt::print("{:<6} {:<4} {:>9}  {}\n", "name", "fam", "duration", "description");
    double total = 0;
    for (const auto& name : names) {
      const auto t = design.build(name);
      total += t.duration();
      fmt::print("{:<6} {:<4} {:>8.1f}s  {}\n", t.name, t.family, t.duration(), t.description);
    }
    fmt::print("{} trajectories, {:.1f} s in all\n", names.size(), total);
    return;
  }
  std::filesystem::create_directories(o.out);
  Progress progress(static_cast<int>(names.size()), "reference");
  for (const auto& name : names) {
    const auto t = design.build(name);
    io::write_log(std::filesystem::path(o.out) / (name + ".csv"), trajectory::reference_log(t, o.period, common.robot, joint_names));
    progress.done(name, fmt::format("{:.1f} s", t.duration()));
  }
}

}  // namespace

void add_trajectory_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<TrajectoryOptions>();
  auto* cmd = app.add_subcommand("trajectories", "List the identification trajectories, or write them as reference files");
  cmd->add_option("--robot", common.robot, "Robot folder name under robots/")->required();
  cmd->add_option("--robots-dir", common.robots_dir, "Where the robot folders are");
  cmd->add_option("-o,--output", o->out, "Write <name>.csv and <name>.meta.yaml here (default: list only)");
  cmd->add_option("--only", o->only, "Only these trajectories");
  cmd->add_option("--period", o->period, "Sample period of the reference files, s")->check(CLI::PositiveNumber);
  cmd->callback([&common, o] {
    if (!with_robot(common.robot, [&](auto entry) { run_trajectories<typename decltype(entry)::FullModel>(common, *o); }))
      throw UsageError("unknown robot '" + common.robot + "'");
  });
}

}  // namespace symoro::dynid
