// A URDF's geometry as both symoroc model (codegen/src/modeling/urdf_chain.cpp) and dynid export
// --into (runtime/tools/dynid_urdf_into.cpp) read it, so that the two agree to the bit: origins
// with quarter turns made exact, and a joint's motion at a position. Header-only (urdfdom's
// types): whoever includes it links urdfdom.
#pragma once

#include <cmath>

#include <Eigen/Geometry>
#include <urdf_model/joint.h>
#include <urdf_model/pose.h>

namespace symoro::urdf_geometry {

// rad: an angle this close to k pi/2 is k pi/2. URDFs write quarter turns to 9 or 11 digits
// (1.570796325, 1.57079632679): they mean pi/2, and exact zeros keep a model's code short.
inline constexpr double kAngleSnap = 1e-8;

inline double snapped_angle(double a) {
  const double k = std::round(a / (M_PI / 2));
  return std::abs(a - k * M_PI / 2) <= kAngleSnap ? k * M_PI / 2 : a;
}

// A rotation entry within rounding of 0 or +-1 is that value (cos(pi/2) is 6e-17 in double).
inline double exact(double v) {
  return std::abs(v) < 1e-15 ? 0.0 : std::abs(std::abs(v) - 1) < 1e-15 ? std::copysign(1.0, v) : v;
}

// A URDF origin; its roll, pitch and yaw near quarter turns taken as exact, so that the geometry
// computed from them is exact too (0.09465, not 0.0946499999959983).
inline Eigen::Isometry3d pose(const urdf::Pose& p) {
  double roll, pitch, yaw;
  p.rotation.getRPY(roll, pitch, yaw);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(snapped_angle(yaw), Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(snapped_angle(pitch), Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(snapped_angle(roll), Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) T.linear()(a, b) = exact(T.linear()(a, b));
  T.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  return T;
}

// A moving joint's motion at position q (fixed, floating and planar joints: none).
inline Eigen::Isometry3d motion(const urdf::Joint& j, double q) {
  Eigen::Isometry3d M = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d axis = Eigen::Vector3d(j.axis.x, j.axis.y, j.axis.z).normalized();
  if (j.type == urdf::Joint::PRISMATIC)
    M.translation() = q * axis;
  else if (j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::CONTINUOUS)
    M.linear() = Eigen::AngleAxisd(q, axis).toRotationMatrix();
  return M;
}

}  // namespace symoro::urdf_geometry
