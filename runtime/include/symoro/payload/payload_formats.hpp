// A payload as the places that take one write it: payload.yaml (dynid payload's result, which
// dynid export and twin overrides read back), a URDF link on a fixed joint, and the load
// settings of three controllers (docs/payload.md cites each):
//   - Franka (libfranka Robot::setLoad): mass kg, F_x_Cload m (CoM in the flange frame F),
//     load_inertia kg m^2 (3 x 3 about the CoM, column-major, axes of F);
//   - UR (URScript set_target_payload(m, cog, inertia)): kg, m from the tool flange, inertia
//     [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] kg m^2 about the CoG, axes of the tool flange;
//   - KUKA KSS load data {M, CM {X, Y, Z, A, B, C}, J {X, Y, Z}}: kg, CoM mm in the flange frame,
//     A B C deg (rotations about Z, then the new Y, then the new X) of the principal axes, J the
//     principal moments about the CoM kg m^2.
// Each in the flange frame the payload was identified in: the controller's flange must be it.
#pragma once

#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "symoro/payload/payload_identification.hpp"
#include "symoro/payload/payload_inertial.hpp"

namespace symoro::payload {

// The flange frame of a robot folder's robot.yaml: the URDF tip link symoroc model recorded
// (urdf.tip_link, its pose urdf.tip_in_last_frame) when the payload rides on the last frame,
// else the payload link's own model frame ("frame <link>"). DataError for a malformed pose.
std::string robot_flange(const std::string& robot_yaml, int link, int frames, Eigen::Isometry3d& flange_in_link);

// What payload.yaml records besides the estimate.
struct PayloadFileContext {
  std::string robot, model, params;  // the arm's robot, model and parameters file
  std::string flange;                // the flange frame's name (a URDF link, or "frame <k>")
  Eigen::Isometry3d flange_in_link = Eigen::Isometry3d::Identity();
  std::string logs;  // what it was identified from
};

std::string payload_yaml(const PayloadEstimate& e, const PayloadFileContext& context);

// payload.yaml's payload (mass, com, inertia) and flange; DataError naming the file and line.
struct PayloadFile {
  PayloadInertial payload;
  std::string robot, flange;
  int link = 0;  // the model frame it rides on, and the flange's pose there
  Eigen::Isometry3d flange_in_link = Eigen::Isometry3d::Identity();
};
PayloadFile read_payload_yaml(const std::string& file);

// <link name> with the payload's <inertial>, and the fixed <joint> that holds it on `parent` with
// the flange at `flange_in_parent`: the text of both, indented by two spaces.
std::string payload_urdf(const PayloadInertial& p, const std::string& parent, const std::string& name = "payload",
                         const Eigen::Isometry3d& flange_in_parent = Eigen::Isometry3d::Identity());

// `urdf` (a whole file's text) with the payload's link and joint before its closing </robot>.
// std::invalid_argument when the file has no </robot>, no link `parent`, or a link `name` already.
std::string urdf_with_payload(const std::string& urdf, const PayloadInertial& p, const std::string& parent,
                              const std::string& name = "payload",
                              const Eigen::Isometry3d& flange_in_parent = Eigen::Isometry3d::Identity());

// The KUKA form: principal moments and the A B C angles (deg) of the principal axes, the axes
// ordered and signed to be nearest the flange's own.
struct PrincipalLoad {
  Eigen::Vector3d moments;  // about the rotated x, y, z
  Eigen::Vector3d abc;      // deg
  Eigen::Matrix3d axes;     // columns: the rotated frame's axes in the flange frame
};
PrincipalLoad principal_load(const Eigen::Matrix3d& inertia);

std::string franka_load(const PayloadInertial& p);  // YAML: mass, F_x_Cload, load_inertia
std::string ur_payload(const PayloadInertial& p);   // a URScript line
std::string kuka_load(const PayloadInertial& p);    // a KRL load data aggregate

}  // namespace symoro::payload
