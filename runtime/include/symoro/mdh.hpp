// One modified Denavit-Hartenberg (Khalil-Kleinfinger) transform, numeric:
// ^{ant}T_j = Rot(z, gamma) Trans(z, b) Rot(x, alpha) Trans(x, d) Rot(z, theta) Trans(z, r),
// with the joint variable q added to theta (revolute) or r (prismatic).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

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

// ^0T_j for every frame j = 1..n (index j - 1), following `ant`. q has one entry per movable
// frame (sigma != 2), in frame order.
inline std::vector<Eigen::Isometry3d> mdh_poses(const std::vector<FrameInfo>& frames, const Eigen::VectorXd& q) {
  const int n = static_cast<int>(frames.size());
  std::vector<Eigen::Isometry3d> T(static_cast<std::size_t>(n));
  int k = 0;
  for (int j = 0; j < n; ++j) {
    const FrameInfo& f = frames[static_cast<std::size_t>(j)];
    const double qj = f.sigma == 2 ? 0.0 : q(k++);
    const Eigen::Isometry3d parent =
        f.ant == 0 ? Eigen::Isometry3d::Identity() : T[static_cast<std::size_t>(f.ant - 1)];
    T[static_cast<std::size_t>(j)] = parent * mdh_transform(f, qj);
  }
  return T;
}

}  // namespace symoro
