// A dataset folder as `dynid twin dataset` writes it (one log per trajectory, trial 1, and the
// manifest), for tests that run the identification or the diagnosis on twin data.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "symoro/io/dataset.hpp"
#include "symoro/io/log.hpp"
#include "symoro/robot/compiled_model.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/simulator.hpp"

namespace symoro::test {

// Writes <dir>/<NAME>_t1.csv for every name (seeds as the dataset command draws them from
// `seed`) and <dir>/dataset.yaml; `twin_file` goes into the manifest when not empty.
template <class Full>
void write_twin_dataset(const std::filesystem::path& dir, const twin::TwinConfig& config,
                        const trajectory::TrajectoryDesign& design, const std::vector<std::string>& names,
                        std::uint64_t seed, const std::string& twin_file = "") {
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const twin::ClosedLoopTwin tw(symoro::robot::compiled_model<Full>(), config);
  io::Dataset d;
  d.dir = dir;
  d.robot = Full::robot_name;
  d.twin = twin_file;
  for (const auto& name : names) {
    twin::RunOptions ro;
    ro.robot = Full::robot_name;
    ro.seed = twin::run_seed(seed, name, 1);
    const auto traj = design.build(name);
    io::write_log(dir / (name + "_t1.csv"), tw.run(traj, ro));
    d.runs.push_back({name, traj.family, 1, name + "_t1.csv"});
  }
  io::write_dataset(d);
}

}  // namespace symoro::test
