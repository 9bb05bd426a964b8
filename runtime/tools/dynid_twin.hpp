// dynid twin's options and its entry, compiled for each robot's full model in generated units;
// the bodies of run, dataset and bench are in dynid_twin-inl.hpp.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "dynid_dispatch.hpp"

namespace symoro::dynid {

struct TwinOptions {
  enum class Mode { run, dataset, bench } mode = Mode::run;  // which subcommand (one entry for all three)
  std::string config;                 // override YAML
  std::vector<std::string> effects;   // enable
  std::vector<std::string> without;   // disable
  bool ideal = false;                 // disable all first
  std::string out;
  std::string trajectory = "AG02";
  std::vector<std::string> only;
  int trial = 1, trials = 3, jobs = 0;
  std::uint64_t seed = 1;
  double repeat_seconds = 3;
};

struct TwinCommand {
  using Options = TwinOptions;
  template <class Full, class Model>
  static void run(const Common& common, const Options& o);
};

const CommandTable<TwinOptions>& twin_units();  // generated: dynid_tables.cpp

}  // namespace symoro::dynid
