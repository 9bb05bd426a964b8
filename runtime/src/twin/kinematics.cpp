#include "symoro/twin/kinematics.hpp"

namespace symoro::twin {

std::vector<Eigen::Isometry3d> mdh_poses(const std::vector<FrameInfo>& frames, const Eigen::VectorXd& q) {
  const int n = static_cast<int>(frames.size());
  std::vector<Eigen::Isometry3d> T(n);
  int k = 0;
  for (int j = 0; j < n; ++j) {
    const FrameInfo& f = frames[j];
    const double qj = f.sigma == 2 ? 0.0 : q(k++);
    const Eigen::Isometry3d parent = f.ant == 0 ? Eigen::Isometry3d::Identity() : T[f.ant - 1];
    T[j] = parent * mdh_transform(f, qj);
  }
  return T;
}

Eigen::Matrix3d rotation_from_rpy(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX())).toRotationMatrix();
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
