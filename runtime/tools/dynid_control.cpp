// dynid control: run a designed trajectory on the real arm (DYNAMIXEL bus at --port) with the
// paper's FF+PD at 1 kHz, or with --virtual on the emulated servo chain driving the digital twin
// (a pseudo-terminal: the same driver, bytes and timing path), and write its log.
#include <fcntl.h>
#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "dynid_control.hpp"
#include "dynid_numbers.hpp"
#include "dynid_robots.hpp"
#include "symoro/control/description.hpp"
#include "symoro/dynamixel/bus.hpp"
#include "symoro/dynamixel/serial_port.hpp"
#include "symoro/dynamixel/virtual_bus.hpp"
#include "symoro/hardware/config.hpp"
#include "symoro/hardware/controller.hpp"
#include "symoro/io/log.hpp"
#include "symoro/io/parameters_yaml.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/simulator.hpp"
#include "symoro/twin_bus/twin_servo_backend.hpp"

namespace symoro::dynid {

namespace {

// The log's path, claimed: -o as given when free, with "new-name" the first free
// <stem>-<k><ext>. The CSV is created empty at once (O_EXCL), so that two runs started together
// never write one log (both used to report its rows while one run was lost); a claim still empty
// when the command ends (it failed before the run) is removed.
class LogClaim {
 public:
  LogClaim(const std::filesystem::path& out, const std::string& if_exists) {
    if (!out.parent_path().empty()) std::filesystem::create_directories(out.parent_path());
    for (int k = 0;; ++k) {
      const auto p =
          k == 0 ? out : out.parent_path() / fmt::format("{}-{}{}", out.stem().string(), k, out.extension().string());
      bool taken = std::filesystem::exists(io::metadata_path(p));
      if (!taken) {
        const int fd = ::open(p.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
        if (fd >= 0) {
          ::close(fd);
          path_ = p;
          return;
        }
        if (errno != EEXIST)
          throw UsageError(fmt::format("cannot create the log {}: {}", p.string(), std::strerror(errno)));
        taken = true;
      }
      if (if_exists != "new-name")
        throw UsageError(fmt::format(
            "{} exists: a run never overwrites a log; choose another -o, or --if-exists new-name", p.string()));
    }
  }
  ~LogClaim() {
    std::error_code ec;
    if (std::filesystem::file_size(path_, ec) == 0 && !ec) std::filesystem::remove(path_, ec);
  }
  LogClaim(const LogClaim&) = delete;
  LogClaim& operator=(const LogClaim&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// hardware.yaml (or --hardware), with --at-stop and --hold-time over its stop; `override` says
// which (empty: none), and is printed.
hardware::HardwareConfig read_hardware(const Common& common, const ControlCliOptions& options,
                                       const std::vector<JointInfo>& joints, std::string& override) {
  const auto hw_path =
      options.hardware.empty() ? common.robot_dir() / "hardware.yaml" : std::filesystem::path(options.hardware);
  if (!std::filesystem::exists(hw_path))
    throw UsageError(
        fmt::format("robot '{}' has no hardware description ({} not found)", common.robot, hw_path.string()));
  hardware::HardwareConfig hw = hardware::read_hardware_config(hw_path, joints);
  // What happens at a stop is the lab's choice in hardware.yaml; an override is said and logged.
  if (!options.at_stop.empty()) {
    hw.safety.at_stop = options.at_stop == "hold" ? hardware::StopAction::hold : hardware::StopAction::torque_off;
    override = fmt::format("--at-stop {}", options.at_stop);
  }
  if (options.hold_time > 0) {
    hw.safety.hold_time = options.hold_time;
    override += fmt::format("{}--hold-time {}", override.empty() ? "" : " ", options.hold_time);
  }
  if (!override.empty())
    fmt::print(stderr, "control: at a stop: {} for {} s then torque off ({} overrides {})\n",
               hardware::to_string(hw.safety.at_stop), hw.safety.hold_time, override, hw_path.string());
  return hw;
}

// The gains are the lab's controller description's, on the real arm and the virtual one alike,
// at hardware.yaml's period.
control::FfpdGains read_gains(const Common& common, int nq, double period) {
  const auto controller_path = common.robot_dir() / control::controller_file_name();
  if (!std::filesystem::exists(controller_path))
    throw UsageError(fmt::format("robot '{}' has no controller description ({} not found): it holds the FF+PD gains",
                                 common.robot, controller_path.string()));
  control::FfpdGains gains = control::read_controller_description(controller_path, nq).gains();
  gains.period = period;
  return gains;
}

// twin.yaml (and --config, --ideal) shape only the emulated arm behind --virtual: its twin, none
// without --virtual.
std::optional<twin::TwinConfig> read_virtual_twin(const Common& common, const ControlCliOptions& options, int nq) {
  if (!options.virtual_bus) {
    if (!options.twin_config.empty() || options.ideal)
      throw UsageError(
          "--config and --ideal change the emulated arm of --virtual only; the real arm's gains come from " +
          (common.robot_dir() / control::controller_file_name()).string());
    return std::nullopt;
  }
  const auto twin_path = common.robot_dir() / "twin.yaml";
  if (!std::filesystem::exists(twin_path))
    throw UsageError(fmt::format("--virtual needs the robot's digital twin ({} not found)", twin_path.string()));
  twin::TwinConfig tc = twin::read_twin_config(twin_path, nq, options.twin_config);
  if (options.ideal) tc.effects.disable_all();
  return tc;
}

// --params: the identified model's feed-forward and inertia for the loop, with what the log
// notes of them.
void add_model_feedforward(const Common& common, const ControlCliOptions& options, hardware::ControlOptions& co) {
  const robot::ModelHandle identified = robot_model(common, "");
  std::vector<std::string> names;
  for (const auto& p : identified.parameters()) names.emplace_back(p.name);
  const Eigen::VectorXd phi = io::read_parameters_yaml(options.params, names);
  // Parameters whose final audit failed may not be positive definite everywhere: their
  // inverse dynamics is no feed-forward for a real arm unless the user says so, and the log
  // records it. The flag counts only in a file as identify wrote it (its digest): an edited
  // value or flag makes it a file of unknown origin. Whatever the file says, the loop checks
  // the model on every reference before torque on (hardware::ControlOptions::inertia).
  const io::ParametersIntegrity integrity = io::parameters_integrity(options.params, names);
  const bool accepted = io::parameters_accepted(options.params);
  if (!accepted || !integrity.intact) {
    const std::string why = !integrity.intact
                                ? "the file is not as identify wrote it: " + integrity.why
                                : "the identification was not accepted (its final all-pose audit failed, or "
                                  "the file has no 'accepted: true')";
    if (!options.unaccepted_params)
      throw UsageError(
          fmt::format("{}: {}; --unaccepted-params drives with it anyway (the model is still checked before "
                      "torque on)",
                      options.params, why));
    co.notes += !integrity.intact ? "; PARAMETERS EDITED OR NOT FROM IDENTIFY (--unaccepted-params)"
                                  : "; PARAMETERS NOT ACCEPTED (--unaccepted-params)";
  }
  co.feedforward = hardware::model_feedforward(identified, phi);
  co.inertia = hardware::model_inertia(identified, phi);
  co.notes += "; model feedforward from " + options.params;
}

// --virtual: the emulated servo chain driving the twin, at the trajectory's start. With
// --rt-priority the emulated servos' thread gets SCHED_FIFO one below the loop (a thread
// inherits its creator's scheduling).
std::unique_ptr<dynamixel::VirtualBus> start_virtual_bus(const ControlCliOptions& options,
                                                         const robot::ModelHandle& full, const twin::TwinConfig& tc,
                                                         const hardware::HardwareConfig& hw,
                                                         const trajectory::Trajectory& traj) {
  Eigen::VectorXd q(full.nq()), qd(full.nq()), qdd(full.nq());
  traj.evaluate(0, q, qd, qdd);
  int policy = 0;
  sched_param saved{};
  bool raised = false;
  if (options.priority > 1) {
    pthread_getschedparam(pthread_self(), &policy, &saved);
    sched_param p{};
    p.sched_priority = options.priority - 1;
    raised = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p) == 0;
  }
  auto virt = std::make_unique<dynamixel::VirtualBus>(twin_bus::virtual_servos(hw),
                                                      std::make_unique<twin_bus::TwinServoBackend>(full, tc, hw, q));
  if (raised) pthread_setschedparam(pthread_self(), policy, &saved);
  return virt;
}

}  // namespace

void run_control_command(const Common& common, const ControlCliOptions& options) {
  // A closed terminal or pipe must neither end a run nor the command: SIGPIPE is ignored until
  // dynid exits (the report is written first, then flushed at exit), and from here on every
  // signal that would end dynid is a stop request.
  std::signal(SIGPIPE, SIG_IGN);
  hardware::StopSignals signals;
  const LogClaim claim(options.out, options.if_exists);  // before anything moves
  const std::string out = claim.path().string();
  const robot::ModelHandle full = full_model(common);
  const std::vector<JointInfo>& joints = full.joints();
  std::string stop_override;
  const hardware::HardwareConfig hw = read_hardware(common, options, joints, stop_override);
  const control::FfpdGains gains = read_gains(common, full.nq(), hw.period);
  const std::optional<twin::TwinConfig> tc = read_virtual_twin(common, options, full.nq());
  const trajectory::Trajectory traj = read_design(common, joints).build(options.trajectory);

  hardware::ControlOptions co;
  co.robot = common.robot;
  co.trial = options.trial;
  co.seconds = options.seconds;
  co.realtime_priority = options.priority;
  // The emulated servos are a thread that may wait for a core on a loaded machine.
  if (!options.virtual_bus && options.watchdog > hardware::kMaxWatchdogCycles)
    throw UsageError(fmt::format("--watchdog {}: at most {} cycles on a real port (the arm runs blind that long)",
                                 options.watchdog, hardware::kMaxWatchdogCycles));
  co.watchdog_cycles =
      options.watchdog > 0 ? options.watchdog : (options.virtual_bus ? std::max(20, hw.safety.watchdog_cycles) : 0);
  co.source = options.virtual_bus ? "twin" : "robot";
  co.notes = options.virtual_bus ? "dynid control --virtual: virtual DYNAMIXEL bus driving the " +
                                       twin::ClosedLoopTwin(full, *tc).notes()
                                 : "dynid control on " + options.port;
  co.notes += fmt::format(
      "; at stop: {}{}", hardware::to_string(hw.safety.at_stop),
      hw.safety.at_stop == hardware::StopAction::hold ? fmt::format(" {} s then torque off", hw.safety.hold_time) : "");
  if (!stop_override.empty()) co.notes += " (" + stop_override + ")";
  if (!options.params.empty()) add_model_feedforward(common, options, co);

  std::unique_ptr<dynamixel::VirtualBus> virt;
  std::string device = options.port;
  if (options.virtual_bus) {
    virt = start_virtual_bus(options, full, *tc, hw, traj);
    device = virt->device();
  }
  dynamixel::SerialPort port(device, hw.baud);
  dynamixel::Bus bus(port);
  const hardware::ControlResult r = hardware::run_control(bus, hw, joints, gains, traj, out, co);
  fmt::print("{}: {} rows, {:.3f} s of {}; max |q_ref - q| per joint (deg):", out, r.rows, r.trajectory_time,
             options.trajectory);
  for (int j = 0; j < r.max_error.size(); ++j) fmt::print(" {:.3f}", r.max_error(j) * 180 / 3.14159265358979323846);
  fmt::print("\nat stop: {}\n{}\n", r.at_stop, r.timing.summary());
  if (r.reason != hardware::StopReason::completed)
    throw std::runtime_error(fmt::format("run stopped ({}): {}; torque off {}", hardware::to_string(r.reason),
                                         r.message,
                                         r.torque_off_confirmed ? "confirmed" : "NOT confirmed for every servo"));
  fmt::print("completed; torque off {}\n", r.torque_off_confirmed ? "confirmed" : "NOT confirmed for every servo");
}

void add_control_commands(CLI::App& app, Common& common) {
  auto o = std::make_shared<ControlCliOptions>();
  auto* cmd = app.add_subcommand("control",
                                 "Run a trajectory on the arm (DYNAMIXEL bus, FF+PD at 1 kHz) and log it; "
                                 "--virtual: on the emulated bus driving the digital twin");
  add_robot_options(cmd, common);
  cmd->add_option("--design", common.design,
                  "A trajectory design file (e.g. dynid excite's) instead of robots/<robot>/trajectories.yaml")
      ->check(CLI::ExistingFile);
  cmd->add_option("--port", o->port, "Serial device of the DYNAMIXEL bus (default /dev/ttyUSB0)");
  cmd->add_flag("--virtual", o->virtual_bus, "Emulated servos on a pseudo-terminal, driving the digital twin");
  cmd->add_option("--trajectory", o->trajectory, "Trajectory name (default AG02)");
  cmd->add_option("-o,--output", o->out, "Log file (CSV; its .meta.yaml sidecar next to it)")->required();
  cmd->add_option("--params", o->params,
                  "A study's report/parameters.yaml: add the identified model's inverse dynamics "
                  "as feedforward")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--unaccepted-params", o->unaccepted_params,
                "Drive with --params whose identification was not "
                "accepted (recorded in the log)");
  cmd->add_option("--if-exists", o->if_exists, "When -o exists: refuse (default) or new-name (<stem>-<k>.csv)")
      ->check(CLI::IsMember({"refuse", "new-name"}));
  cmd->add_option("--seconds", o->seconds, "Run only this much of the trajectory")
      ->check(numbers::positive(1e6, "> 0 and <= 1e6 s"));
  cmd->add_option("--hardware", o->hardware, "Hardware description (default robots/<robot>/hardware.yaml)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--config", o->twin_config, "--virtual: a YAML file overriding parts of twin.yaml")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--ideal", o->ideal, "--virtual: turn every twin effect off");
  cmd->add_option("--trial", o->trial, "Trial number in the log")->check(numbers::count(1, 1e6));
  cmd->add_option("--watchdog", o->watchdog,
                  "Consecutive failed reads that stop the arm (default: hardware.yaml's; "
                  "--virtual: at least 20)")
      ->check(numbers::count(1, 1e6));
  cmd->add_option("--at-stop", o->at_stop,
                  "At a stop with torque on: hold the stop pose for the hold time, then torque off; "
                  "or torque-off at once (default: hardware.yaml's safety.at_stop; logged)")
      ->check(CLI::IsMember({"hold", "torque-off"}));
  cmd->add_option("--hold-time", o->hold_time,
                  "Seconds of hold at a stop (default: hardware.yaml's safety.hold_time; logged)")
      ->check(numbers::positive(600, "> 0 and <= 600 s"));
  cmd->add_option("--rt-priority", o->priority,
                  "SCHED_FIFO priority of the loop (default 30; 0: normal scheduling; refused: normal, with a note)")
      ->check(numbers::count(0, 99));
  cmd->callback([&common, o] { run_control_command(common, *o); });
}

}  // namespace symoro::dynid
