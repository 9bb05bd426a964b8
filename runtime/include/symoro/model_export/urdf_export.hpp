// A robot model with a standard parameter vector as URDF (dynid export --urdf): one link per
// model frame (the modified-DH frames of Khalil-Kleinfinger, frame 0 the base link), one joint
// per frame whose origin is the frame's constant transform (the transform at q = 0) and whose
// axis is z, so that each URDF link frame IS the model frame; each link's inertial (mass, CoM,
// inertia about the CoM in the link frame) from the frame-origin parameters XX..ZZ, MX MY MZ, M;
// joint damping FV and friction FS. Rotor inertia IA has no URDF field: a comment says so, and
// the standard-parameter YAML/CSV written next to the URDF carries it.
// For a generated Model, urdf_description<Model>() fills the description; the writer itself
// takes plain data (no robot header).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/model_info.hpp"

namespace symoro::model_export {

struct UrdfDescription {
  std::string robot;                         // <robot name="...">
  std::vector<FrameInfo> frames;             // frames 1..nf (entry i: frame i + 1)
  std::vector<JointInfo> joints;             // the movable frames, in frame order
  std::vector<StandardParameterInfo> names;  // the entries of s
  Eigen::VectorXd s;                         // standard parameters
  std::vector<std::string> notes;            // comment lines after the convention (provenance)
};

// One link's inertial as URDF has it. `present` is false when the model has no inertial
// parameter for the frame, or all of them are 0 (a massless frame such as CRANE-X7's hand axis):
// the link is then written without <inertial> (URDF allows that; a simulator may need a tiny one).
struct UrdfInertial {
  bool present = false;
  double mass = 0;
  Eigen::Vector3d com = Eigen::Vector3d::Zero();      // in the link (model) frame
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  // about the CoM, link-frame axes
};

// Frame-origin parameters (inertia I about the frame origin, first moments h = m c, mass m) to
// URDF's CoM form: c = h / m (0 when m = 0), I_c = I - m (|c|^2 1 - c c'). And back.
UrdfInertial inertial_about_com(const Eigen::Matrix3d& inertia_origin, const Eigen::Vector3d& first_moment,
                                double mass);
void inertial_about_origin(const UrdfInertial& in, Eigen::Matrix3d& inertia_origin, Eigen::Vector3d& first_moment,
                           double& mass);

// The inertial of frame `frame` (1..nf) from s, by the families of `names`.
UrdfInertial link_inertial(const UrdfDescription& d, int frame);

// Names: frame 0 "base_link"; a movable frame "<joint name>_link"; a fixed frame j "frame<j>_link".
// Joints: a movable frame's joint name; a fixed frame j "frame<j>_fixed".
std::string urdf_link_name(const UrdfDescription& d, int frame);
std::string urdf_joint_name(const UrdfDescription& d, int frame);

// URDF's rpy of a rotation: R = Rz(yaw) Ry(pitch) Rx(roll), returned as (roll, pitch, yaw).
Eigen::Vector3d urdf_rpy(const Eigen::Matrix3d& R);

// The URDF text. Numbers are the shortest decimal that reads back as the same double (at most
// 17 significant digits). Throws std::invalid_argument on inconsistent sizes or duplicate names.
std::string urdf_text(const UrdfDescription& d);

// The standard parameters as YAML (a `parameters:` list of {name, frame, family, unit, value},
// readable by io::read_parameters_yaml and by dynid export --prior) and as CSV (name,frame,
// family,unit,value); `header` lines go first as YAML comments / key-values given verbatim.
std::string standard_parameters_yaml(const UrdfDescription& d, const std::string& header);
std::string standard_parameters_csv(const UrdfDescription& d);

// The unit of a standard parameter (family, and whether its joint is prismatic).
std::string standard_unit(const std::string& family, bool prismatic);

template <class Model>
UrdfDescription urdf_description(const Eigen::VectorXd& s) {
  UrdfDescription d;
  d.robot = Model::robot_name;
  d.frames.assign(Model::frames.begin(), Model::frames.end());
  d.joints.assign(Model::joints.begin(), Model::joints.end());
  d.names.assign(Model::standard_parameters.begin(), Model::standard_parameters.end());
  d.s = s;
  return d;
}

}  // namespace symoro::model_export
