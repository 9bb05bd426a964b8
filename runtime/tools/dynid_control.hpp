// dynid control's options and its body: the robot's full model (the arm, and its twin behind
// --virtual) and its identified model (--params' feedforward).
#pragma once

#include <string>

#include "dynid_common.hpp"

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
  bool unaccepted_params = false;    // drive with parameters whose identification was not accepted
  std::string if_exists = "refuse";  // or "new-name": the log never overwrites one
  std::string at_stop;               // "", "hold" or "torque-off": overrides hardware.yaml's safety.at_stop
  double hold_time = 0;              // s; 0: hardware.yaml's safety.hold_time
};

void run_control_command(const Common& common, const ControlCliOptions& options);

}  // namespace symoro::dynid
