// dynid trajectories' body for one robot (included by the generated units only): the design
// listed, or written as reference files.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "dynid_trajectories.hpp"
#include "symoro/io/log.hpp"
#include "symoro/trajectory/design.hpp"

namespace symoro::dynid {

template <class Full, class Model>
void TrajectoriesCommand::run(const Common& common, const TrajectoryOptions& o) {
  const auto design = trajectory::TrajectoryDesign::read(common.design_path(), joint_list<Full>());
  const std::vector<std::string> names = o.only.empty() ? design.names() : o.only;
  std::vector<std::string> joint_names;
  for (const auto& j : Full::joints) joint_names.push_back(j.name);
  if (o.out.empty() && o.quality) {
    std::vector<trajectory::Trajectory> all;
    for (const auto& name : names) all.push_back(design.build(name));
    fmt::print("{}", trajectory_quality_table(common, all, o));
    return;
  }
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

}  // namespace symoro::dynid
