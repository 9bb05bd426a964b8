// dynid control's options and its entry, compiled for each robot's full model (the arm and its
// twin) and identified model (--params' feedforward) in generated units; the body is in
// dynid_control-inl.hpp.
#pragma once

#include <string>

#include "dynid_dispatch.hpp"

namespace symoro::dynid {

struct ControlCliOptions {
  std::string port = "/dev/ttyUSB0";
  bool virtual_bus = false;
  std::string trajectory = "AG02";
  std::string out;
  std::string params;
  std::string hardware;  // default robots/<robot>/hardware.yaml
  std::string twin_config;
  bool ideal = false;
  double seconds = 0;
  int trial = 1;
  int priority = 30;  // SCHED_FIFO when the system allows it (else normal scheduling, said once)
  int watchdog = 0;
  bool unaccepted_params = false;  // drive with parameters whose identification was not accepted
  std::string if_exists = "refuse";  // or "new-name": the log never overwrites one
  std::string at_stop;   // "", "hold" or "torque-off": overrides hardware.yaml's safety.at_stop
  double hold_time = 0;  // s; 0: hardware.yaml's safety.hold_time
};

struct ControlCommand {
  using Options = ControlCliOptions;
  template <class Full, class Identified>
  static void run(const Common& common, const Options& o);
};

const CommandTable<ControlCliOptions>& control_units();  // generated: dynid_tables.cpp

}  // namespace symoro::dynid
