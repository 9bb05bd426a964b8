// One modified Denavit-Hartenberg (Khalil-Kleinfinger) transform, numeric:
// ^{ant}T_j = Rot(z, gamma) Trans(z, b) Rot(x, alpha) Trans(x, d) Rot(z, theta) Trans(z, r),
// with the joint variable q added to theta (revolute) or r (prismatic).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "symoro/model_info.hpp"

namespace symoro {

inline Eigen::Isometry3d mdh_transform(const FrameInfo& f, double q) {
  const double theta = f.theta + (f.sigma == 0 ? q : 0.0);
  const double r = f.r + (f.sigma == 1 ? q : 0.0);
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ(), x = Eigen::Vector3d::UnitX();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.rotate(Eigen::AngleAxisd(f.gamma, z)).translate(f.b * z);
  T.rotate(Eigen::AngleAxisd(f.alpha, x)).translate(f.d * x);
  T.rotate(Eigen::AngleAxisd(theta, z)).translate(r * z);
  return T;
}

}  // namespace symoro
