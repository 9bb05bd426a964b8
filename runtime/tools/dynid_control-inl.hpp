// dynid control's body for one robot (included by the generated units only): the FF+PD run on
// the real bus or the virtual one driving the twin, and its log.
#pragma once

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "dynid_control.hpp"
#include "symoro/control/description.hpp"
#include "symoro/dynamixel/bus.hpp"
#include "symoro/dynamixel/serial_port.hpp"
#include "symoro/dynamixel/virtual_bus.hpp"
#include "symoro/hardware/config.hpp"
#include "symoro/hardware/controller.hpp"
#include "symoro/io/log.hpp"
#include "symoro/io/parameters_yaml.hpp"
#include "symoro/twin_bus/twin_servo_backend.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/simulator.hpp"

namespace symoro::dynid {

namespace control_detail {

// The log's path: -o as given when free; with "new-name" the first free <stem>-<k><ext>.
inline std::filesystem::path free_log_path(const std::filesystem::path& out, const std::string& if_exists) {
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

}  // namespace control_detail

template <class Full, class Identified>
void ControlCommand::run(const Common& common, const ControlCliOptions& o) {
  const std::string out = control_detail::free_log_path(o.out, o.if_exists).string();  // before anything moves
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
      trajectory::TrajectoryDesign::read(common.design_path(), joints).build(o.trajectory);

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
    // records it. The flag counts only in a file as identify wrote it (its digest): an edited
    // value or flag makes it a file of unknown origin. Whatever the file says, the loop checks
    // the model on every reference before torque on (hardware::ControlOptions::inertia).
    const io::ParametersIntegrity integrity = io::parameters_integrity(o.params, names);
    const bool accepted = io::parameters_accepted(o.params);
    if (!accepted || !integrity.intact) {
      const std::string why = !integrity.intact ? "the file is not as identify wrote it: " + integrity.why
                                                : "the identification was not accepted (its final all-pose audit failed, or "
                                                  "the file has no 'accepted: true')";
      if (!o.unaccepted_params)
        throw UsageError(fmt::format("{}: {}; --unaccepted-params drives with it anyway (the model is still checked before "
                                     "torque on)",
                                     o.params, why));
      co.notes += !integrity.intact ? "; PARAMETERS EDITED OR NOT FROM IDENTIFY (--unaccepted-params)"
                                    : "; PARAMETERS NOT ACCEPTED (--unaccepted-params)";
    }
    co.feedforward = hardware::model_feedforward<Identified>(phi);
    co.inertia = hardware::model_inertia<Identified>(phi);
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
        twin_bus::virtual_servos(hw),
        std::make_unique<twin_bus::TwinServoBackend<Full>>(*tc, hw, Eigen::Matrix<double, Full::nq, 1>(q)));
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

}  // namespace symoro::dynid
