// dynid twin's options: one run, a whole dataset, or the speed measurement, on any robot with a
// twin.yaml (its full model's handle drives the plant).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "dynid_common.hpp"
#include "symoro/twin/dataset.hpp"

namespace symoro::dynid {

struct TwinOptions {
  enum class Mode { run, dataset, bench } mode = Mode::run;  // which subcommand (one entry for all three)
  std::string config;                                        // override YAML
  std::vector<std::string> effects;                          // enable
  std::vector<std::string> without;                          // disable
  bool ideal = false;                                        // disable all first
  std::string out;
  std::string trajectory = "AG02";
  std::vector<std::string> only;
  int trial = 1, jobs = 0;
  int trials = twin::TwinDatasetOptions{}.trials;
  std::uint64_t seed = twin::TwinDatasetOptions{}.seed;
  double repeat_seconds = 3;
};

void run_twin(const Common& common, const TwinOptions& options);

}  // namespace symoro::dynid
