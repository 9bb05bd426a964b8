// dynid control: run a designed trajectory on the real arm (DYNAMIXEL bus at --port) with the
// paper's FF+PD at 1 kHz, or with --virtual on the emulated servo chain driving the digital twin
// (a pseudo-terminal: the same driver, bytes and timing path), and write its log.
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "dynid_common.hpp"
#include "symoro/control/description.hpp"
#include "symoro/dynamixel/bus.hpp"
#include "symoro/dynamixel/serial_port.hpp"
#include "symoro/dynamixel/virtual_bus.hpp"
#include "symoro/hardware/config.hpp"
#include "symoro/hardware/controller.hpp"
#include "symoro/io/log.hpp"
#include "symoro/io/parameters_yaml.hpp"
#include "symoro/hardware/twin_servo_backend.hpp"
#include "symoro/robots_registry.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/simulator.hpp"

namespace symoro::dynid {

namespace {

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

// The log's path: -o as given when free; with "new-name" the first free <stem>-<k><ext>.
std::filesystem::path free_log_path(const std::filesystem::path& out, const std::string& if_exists) {
  auto taken = [](const std::filesystem::path& p) {
    return std::filesystem::exists(p) || std::filesystem::exists(io::metadata_path(p));
  };
  if (!taken(out)) return out;
  if (if_exists != "new-name")
    throw UsageError(fmt::format("{} exists: a run never overwrites a log; choose another -o, or --if-exists new-name",
                                 out.string()));
  for (int k = 1;; ++k) {
    const auto p = out.parent_path() / fmt::format("{}-{}{}", out.stem().string(), k, out.extension().string());
    if (!taken(p)) return p;
  }
}

template <class Full, class Identified>
void control(const Common& common, const ControlCliOptions& o) {
  const std::string out = free_log_path(o.out, o.if_exists).string();  // before anything moves
  const std::vector<JointInfo> joints = joint_list<Full>();
  const auto hw_path = o.hardware.empty() ? common.robot_dir() / "hardware.yaml" : std::filesystem::path(o.hardware);
  if (!std::filesystem::exists(hw_path))
    throw UsageError(fmt::format("robot '{}' has no hardware description ({} not found)", common.robot, hw_path.string()));
  hardware::HardwareConfig hw = hardware::read_hardware_config(hw_path, joints);
  // What happens at a stop is the lab's choice in hardware.yaml; an override is said and logged.
  std::string stop_override;
  if (!o.at_stop.empty()) {
    hw.safety.at_stop = o.at_stop == "hold" ? hardware::StopAction::hold : hardware::StopAction::torque_off;
    stop_override = fmt::format("--at-stop {}", o.at_stop);
  }
  if (o.hold_time > 0) {
    hw.safety.hold_time = o.hold_time;
    stop_override += fmt::format("{}--hold-time {}", stop_override.empty() ? "" : " ", o.hold_time);
  }
  if (!stop_override.empty())
    fmt::print(stderr, "control: at a stop: {} for {} s then torque off ({} overrides {})\n", hardware::to_string(hw.safety.at_stop),
               hw.safety.hold_time, stop_override, hw_path.string());
  // The gains are the lab's controller description's, on the real arm and the virtual one alike;
  // twin.yaml (and --config, --ideal) shape only the emulated arm behind --virtual.
  const auto controller_path = common.robot_dir() / control::controller_file_name();
  if (!std::filesystem::exists(controller_path))
    throw UsageError(fmt::format("robot '{}' has no controller description ({} not found): it holds the FF+PD gains",
                                 common.robot, controller_path.string()));
  control::FfpdGains gains = control::read_controller_description(controller_path, Full::nq).gains();
  gains.period = hw.period;
  if (!o.virtual_bus && (!o.twin_config.empty() || o.ideal))
    throw UsageError("--config and --ideal change the emulated arm of --virtual only; the real arm's gains come from " +
                     controller_path.string());
  std::optional<twin::TwinConfig> tc;
  if (o.virtual_bus) {
    const auto twin_path = common.robot_dir() / "twin.yaml";
    if (!std::filesystem::exists(twin_path))
      throw UsageError(fmt::format("--virtual needs the robot's digital twin ({} not found)", twin_path.string()));
    tc = twin::read_twin_config(twin_path, Full::nq, o.twin_config);
    if (o.ideal) tc->effects.disable_all();
  }
  const trajectory::Trajectory traj =
      trajectory::TrajectoryDesign::read(common.robot_dir() / "trajectories.yaml", joints).build(o.trajectory);

  hardware::ControlOptions co;
  co.robot = common.robot;
  co.trial = o.trial;
  co.seconds = o.seconds;
  co.realtime_priority = o.priority;
  // The emulated servos are a thread that may wait for a core on a loaded machine.
  if (!o.virtual_bus && o.watchdog > hardware::kMaxWatchdogCycles)
    throw UsageError(fmt::format("--watchdog {}: at most {} cycles on a real port (the arm runs blind that long)", o.watchdog,
                                 hardware::kMaxWatchdogCycles));
  co.watchdog_cycles = o.watchdog > 0 ? o.watchdog : (o.virtual_bus ? std::max(20, hw.safety.watchdog_cycles) : 0);
  co.source = o.virtual_bus ? "twin" : "robot";
  co.notes = o.virtual_bus ? "dynid control --virtual: virtual DYNAMIXEL bus driving the " + twin::ClosedLoopTwin<Full>(*tc).notes()
                           : "dynid control on " + o.port;
  co.notes += fmt::format("; at stop: {}{}", hardware::to_string(hw.safety.at_stop),
                          hw.safety.at_stop == hardware::StopAction::hold ? fmt::format(" {} s then torque off", hw.safety.hold_time) : "");
  if (!stop_override.empty()) co.notes += " (" + stop_override + ")";
  if (!o.params.empty()) {
    std::vector<std::string> names;
    for (const auto& p : Identified::parameters) names.emplace_back(p.name);
    const Eigen::VectorXd phi = io::read_parameters_yaml(o.params, names);
    // Parameters whose final audit failed may not be positive definite everywhere: their
    // inverse dynamics is no feed-forward for a real arm unless the user says so, and the log
    // records it.
    if (!io::parameters_accepted(o.params)) {
      if (!o.unaccepted_params)
        throw UsageError(fmt::format("{}: the identification was not accepted (its final all-pose audit failed, or the "
                                     "file has no 'accepted: true'); --unaccepted-params drives with it anyway",
                                     o.params));
      co.notes += "; PARAMETERS NOT ACCEPTED (--unaccepted-params)";
    }
    co.feedforward = hardware::model_feedforward<Identified>(phi);
    co.notes += "; model feedforward from " + o.params;
  }

  std::unique_ptr<dynamixel::VirtualBus> virt;
  std::string device = o.port;
  if (o.virtual_bus) {
    Eigen::VectorXd q(Full::nq), qd(Full::nq), qdd(Full::nq);
    traj.evaluate(0, q, qd, qdd);
    // With --rt-priority the emulated servos' thread gets SCHED_FIFO one below the loop (a
    // thread inherits its creator's scheduling).
    int policy = 0;
    sched_param saved{};
    bool raised = false;
    if (o.priority > 1) {
      pthread_getschedparam(pthread_self(), &policy, &saved);
      sched_param p{};
      p.sched_priority = o.priority - 1;
      raised = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p) == 0;
    }
    virt = std::make_unique<dynamixel::VirtualBus>(
        hardware::virtual_servos(hw),
        std::make_unique<hardware::TwinServoBackend<Full>>(*tc, hw, Eigen::Matrix<double, Full::nq, 1>(q)));
    if (raised) pthread_setschedparam(pthread_self(), policy, &saved);
    device = virt->device();
  }
  dynamixel::SerialPort port(device, hw.baud);
  dynamixel::Bus bus(port);
  hardware::StopSignals signals;
  const hardware::ControlResult r = hardware::run_control(bus, hw, joints, gains, traj, out, co);
  fmt::print("{}: {} rows, {:.3f} s of {}; max |q_ref - q| per joint (deg):", out, r.rows, r.trajectory_time, o.trajectory);
  for (int j = 0; j < r.max_error.size(); ++j) fmt::print(" {:.3f}", r.max_error(j) * 180 / 3.14159265358979323846);
  fmt::print("\nat stop: {}\n{}\n", r.at_stop, r.timing.summary());
  if (r.reason != hardware::StopReason::completed)
    throw std::runtime_error(fmt::format("run stopped ({}): {}; torque off {}", hardware::to_string(r.reason), r.message,
                                         r.torque_off_confirmed ? "confirmed" : "NOT confirmed for every servo"));
  fmt::print("completed; torque off {}\n", r.torque_off_confirmed ? "confirmed" : "NOT confirmed for every servo");
}

}  // namespace

void add_control_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<ControlCliOptions>();
  auto* cmd = app.add_subcommand("control", "Run a trajectory on the arm (DYNAMIXEL bus, FF+PD at 1 kHz) and log it; "
                                            "--virtual: on the emulated bus driving the digital twin");
  cmd->add_option("--robot", common.robot, "Robot folder name under robots/")->required();
  cmd->add_option("--robots-dir", common.robots_dir, "Where the robot folders are");
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
  cmd->add_option("--seconds", o->seconds, "Run only this much of the trajectory")->check(CLI::PositiveNumber);
  cmd->add_option("--hardware", o->hardware, "Hardware description (default robots/<robot>/hardware.yaml)")->check(CLI::ExistingFile);
  cmd->add_option("--config", o->twin_config, "--virtual: a YAML file overriding parts of twin.yaml")->check(CLI::ExistingFile);
  cmd->add_flag("--ideal", o->ideal, "--virtual: turn every twin effect off");
  cmd->add_option("--trial", o->trial, "Trial number in the log")->check(CLI::PositiveNumber);
  cmd->add_option("--watchdog", o->watchdog, "Consecutive failed reads that stop the arm (default: hardware.yaml's; "
                                             "--virtual: at least 20)")->check(CLI::PositiveNumber);
  cmd->add_option("--at-stop", o->at_stop, "At a stop with torque on: hold the stop pose for the hold time, then torque off; "
                                           "or torque-off at once (default: hardware.yaml's safety.at_stop; logged)")
      ->check(CLI::IsMember({"hold", "torque-off"}));
  cmd->add_option("--hold-time", o->hold_time, "Seconds of hold at a stop (default: hardware.yaml's safety.hold_time; logged)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--rt-priority", o->priority, "SCHED_FIFO priority of the loop (default 30; 0: normal scheduling; refused: normal, with a note)");
  cmd->callback([&common, o] {
    if (!with_robot(common.robot, [&](auto e) {
          control<typename decltype(e)::FullModel, typename decltype(e)::IdentifiedModel>(common, *o);
        }))
      throw UsageError("unknown robot '" + common.robot + "'");
  });
}

}  // namespace symoro::dynid
