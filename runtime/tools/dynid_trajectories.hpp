// dynid trajectories' options and its entry, compiled for each robot's full model in generated
// units; the body is in dynid_trajectories-inl.hpp.
#pragma once

#include <string>
#include <vector>

#include "dynid_dispatch.hpp"

namespace symoro::dynid {

struct TrajectoryOptions {
  std::string out;
  std::vector<std::string> only;
  double period = 0.001;
};

struct TrajectoriesCommand {
  using Options = TrajectoryOptions;
  template <class Full, class Model>
  static void run(const Common& common, const Options& o);
};

const CommandTable<TrajectoryOptions>& trajectories_units();  // generated: dynid_tables.cpp

}  // namespace symoro::dynid
