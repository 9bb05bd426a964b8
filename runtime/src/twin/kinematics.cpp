#include "symoro/twin/kinematics.hpp"

namespace symoro::twin {

Eigen::Matrix3d rotation_from_rpy(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

std::vector<Eigen::Isometry3d> urdf_poses(const UrdfChain& chain, const Eigen::VectorXd& q) {
  std::vector<Eigen::Isometry3d> T;
  Eigen::Isometry3d current = Eigen::Isometry3d::Identity();
  for (const UrdfJoint& j : chain.joints) {
    Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
    origin.translation() = j.xyz;
    origin.linear() = rotation_from_rpy(j.rpy);
    current = current * origin;
    if (!j.fixed) current.rotate(Eigen::AngleAxisd(q(j.model_joint - 1), j.axis));
    T.push_back(current);
  }
  return T;
}

}  // namespace symoro::twin
