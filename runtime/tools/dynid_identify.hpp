// dynid identify's options and its entry, compiled per model of each robot (any variant:
// --model) in generated units; the body is in dynid_identify-inl.hpp.
#pragma once

#include <string>
#include <vector>

#include "dynid_dispatch.hpp"

namespace symoro::dynid {

struct IdentifyOptions {
  std::string data, out, model;
  std::vector<double> intervals_ms;
  std::vector<std::string> only, validation;
  int threads = 0, trial = 1;
  bool weighted = false, no_report = false, fresh = false, in_process = false, physical_start = false;
  int clie_iterations = 25;
  double validation_ms = 0;
  double torque_delay_ms = 0;
  std::string projection_metric = "information";
  std::string consistency = "pd";
  std::string rescue_metric = "all";
  double clie_std_bound = 0;
  double clie_noise_floor = 0;  // identify::ClieOptions::noise_floor
  double rank_timeout = 60;
};

struct IdentifyCommand {
  using Options = IdentifyOptions;
  template <class Full, class Model>
  static void run(const Common& common, const Options& o);
};

const CommandTable<IdentifyOptions>& identify_units();  // generated: dynid_tables.cpp

}  // namespace symoro::dynid
