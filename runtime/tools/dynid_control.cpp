// dynid control: run a designed trajectory on the real arm (DYNAMIXEL bus at --port) with the
// paper's FF+PD at 1 kHz, or with --virtual on the emulated servo chain driving the digital twin
// (a pseudo-terminal: the same driver, bytes and timing path), and write its log.
#include <CLI/CLI.hpp>

#include "dynid_control.hpp"
#include "dynid_numbers.hpp"

namespace symoro::dynid {

void add_control_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<ControlCliOptions>();
  auto* cmd = app.add_subcommand("control", "Run a trajectory on the arm (DYNAMIXEL bus, FF+PD at 1 kHz) and log it; "
                                            "--virtual: on the emulated bus driving the digital twin");
  add_robot_options(cmd, common);
  cmd->add_option("--design", common.design, "A trajectory design file (e.g. dynid excite's) instead of robots/<robot>/trajectories.yaml")
      ->check(CLI::ExistingFile);
  cmd->add_option("--port", o->port, "Serial device of the DYNAMIXEL bus (default /dev/ttyUSB0)");
  cmd->add_flag("--virtual", o->virtual_bus, "Emulated servos on a pseudo-terminal, driving the digital twin");
  cmd->add_option("--trajectory", o->trajectory, "Trajectory name (default AG02)");
  cmd->add_option("-o,--output", o->out, "Log file (CSV; its .meta.yaml sidecar next to it)")->required();
  cmd->add_option("--params", o->params, "A study's report/parameters.yaml: add the identified model's inverse dynamics "
                                         "as feedforward")->check(CLI::ExistingFile);
  cmd->add_flag("--unaccepted-params", o->unaccepted_params, "Drive with --params whose identification was not "
                                                             "accepted (recorded in the log)");
  cmd->add_option("--if-exists", o->if_exists, "When -o exists: refuse (default) or new-name (<stem>-<k>.csv)")
      ->check(CLI::IsMember({"refuse", "new-name"}));
  cmd->add_option("--seconds", o->seconds, "Run only this much of the trajectory")->check(numbers::positive(1e6, "> 0 and <= 1e6 s"));
  cmd->add_option("--hardware", o->hardware, "Hardware description (default robots/<robot>/hardware.yaml)")->check(CLI::ExistingFile);
  cmd->add_option("--config", o->twin_config, "--virtual: a YAML file overriding parts of twin.yaml")->check(CLI::ExistingFile);
  cmd->add_flag("--ideal", o->ideal, "--virtual: turn every twin effect off");
  cmd->add_option("--trial", o->trial, "Trial number in the log")->check(numbers::count(1, 1e6));
  cmd->add_option("--watchdog", o->watchdog, "Consecutive failed reads that stop the arm (default: hardware.yaml's; "
                                             "--virtual: at least 20)")->check(numbers::count(1, 1e6));
  cmd->add_option("--at-stop", o->at_stop, "At a stop with torque on: hold the stop pose for the hold time, then torque off; "
                                           "or torque-off at once (default: hardware.yaml's safety.at_stop; logged)")
      ->check(CLI::IsMember({"hold", "torque-off"}));
  cmd->add_option("--hold-time", o->hold_time, "Seconds of hold at a stop (default: hardware.yaml's safety.hold_time; logged)")
      ->check(numbers::positive(600, "> 0 and <= 600 s"));
  cmd->add_option("--rt-priority", o->priority, "SCHED_FIFO priority of the loop (default 30; 0: normal scheduling; refused: normal, with a note)")
      ->check(numbers::count(0, 99));
  cmd->callback([&common, o] { control_units().robot(common)(common, *o); });
}

}  // namespace symoro::dynid
