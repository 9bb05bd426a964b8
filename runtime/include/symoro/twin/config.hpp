// The digital twin's configuration (robots/<robot>/twin.yaml): the robot's "truth" (a URDF-like
// chain with CAD inertials, drive inertia and friction), its servos, the controller that
// realizes the trajectories, the integrator, and the switchable effects. Read once, validated
// with file and line; everything downstream works on these plain structs.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "symoro/control/description.hpp"

namespace symoro::twin {

struct UrdfJoint {
  std::string name;
  bool fixed = false;
  int model_joint = 0;  // 1-based joint of the model; 0 when fixed
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero(), rpy = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
};

// A rigid body's inertial in URDF form, fixed to the child link of URDF joint `on`.
struct UrdfInertial {
  std::string name;
  std::string on;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // fixed offset of the body in that link
  double mass = 0;
  Eigen::Vector3d com = Eigen::Vector3d::Zero(), rpy = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  // about the CoM, in the rpy frame
};

struct UrdfChain {
  Eigen::Isometry3d base_in_urdf = Eigen::Isometry3d::Identity();  // model frame 0 in the URDF base
  std::vector<UrdfJoint> joints;
  std::vector<UrdfInertial> inertials;
};

struct Servo {
  std::string model;
  double torque_constant = 0;  // N m / A
  double current_unit = 0;     // A per count
  double current_limit = 0;    // A
  int encoder_counts = 0;      // per revolution
};

// The controller that realizes the trajectories: robots/<robot>/controller.yaml (the same
// description identification and the real arm's loop read); an override file may change it.
using ControllerConfig = control::ControllerDescription;

struct Effects {
  bool coulomb = false;
  Eigen::VectorXd coulomb_torque;
  double coulomb_smoothing_velocity = 0.01;
  bool stribeck = false;
  Eigen::VectorXd stribeck_torque;
  double stribeck_velocity = 0.05;
  bool torque_offset = false;
  Eigen::VectorXd offset_torque;
  bool backlash = false;
  Eigen::VectorXd backlash_width;   // rad, total play; 0 = rigid joint
  double backlash_frequency = 100;  // Hz
  double backlash_damping_ratio = 0.1;
  bool payload = false;
  double payload_mass = 0;
  Eigen::Vector3d payload_com = Eigen::Vector3d::Zero();
  // kg m^2 about the payload's CoM, in the link's model frame (0: a point mass).
  Eigen::Matrix3d payload_inertia = Eigen::Matrix3d::Zero();
  bool torque_constant_error = false;
  Eigen::VectorXd torque_constant_scale;
  // The torque lags the current the servo reports (and the controller assumes) by this time:
  // an unmodelled latency of the current loop and driver, on every joint.
  bool actuation_delay = false;
  double actuation_delay_time = 0;  // s
  bool sensor_noise = false;
  double encoder_noise = 0;  // counts
  // Per joint (counts), when given: replaces encoder_noise (the diagnosis estimates it per joint).
  Eigen::VectorXd encoder_noise_per_joint;
  double current_noise = 0;  // A
  bool timestamp_jitter = false;
  double jitter_std = 0, jitter_max = 0;
  bool dropped_samples = false;
  double drop_probability = 0;
  int drop_max_burst = 1;
  // An external torque on one joint's link (a collision; the momentum observer's test input):
  // contact_torque N m (N) from contact_start for contact_duration s of log time, with 2 ms
  // linear ramps inside that span. Optional in twin.yaml (off when absent).
  bool contact = false;
  int contact_joint = 1;  // 1-based
  double contact_start = 0, contact_duration = 0, contact_torque = 0;
  // The contact's torque on its joint at log time t.
  double contact_at(double t) const;

  // Turns every effect off (the ideal twin: only the servos' quantization and the delay).
  void disable_all();
  // Sets one effect on or off by its twin.yaml name; throws std::invalid_argument if unknown.
  void set(const std::string& name, bool enabled);
  static const std::vector<std::string>& names();
  std::vector<std::string> enabled() const;
};

struct TwinConfig {
  std::string path;
  std::string fingerprint;  // hash of the configuration files' bytes: logs record it
  UrdfChain chain;
  Eigen::VectorXd rotor_inertia, viscous;
  std::vector<Servo> servos;
  ControllerConfig controller;
  double max_step = 0.0005;
  Effects effects;
};

// Reads twin.yaml for a robot with `joints` joints, and the controller description beside it
// (controller.yaml) unless twin.yaml has its own `controller` section. `override_path` (optional, may be empty):
// a second YAML file whose keys replace those of the first (maps merge, other values replace),
// for experiments that change a few effects. Errors name the file and line.
TwinConfig read_twin_config(const std::filesystem::path& path, int joints,
                            const std::filesystem::path& override_path = {});

}  // namespace symoro::twin
