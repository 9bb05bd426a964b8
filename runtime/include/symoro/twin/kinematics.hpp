// Forward kinematics of the two descriptions the twin reconciles: the model's modified
// Denavit-Hartenberg frames (Model::frames) and a URDF chain (twin.yaml). Plain double code;
// the twin uses it to map CAD inertials into the model's link frames and to check the mapping.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "symoro/mdh.hpp"
#include "symoro/model_info.hpp"
#include "symoro/twin/config.hpp"

namespace symoro::twin {

// The model's frames: symoro/mdh.hpp.
using symoro::mdh_poses;

// The pose in the URDF base of the child link of every URDF joint (index as chain.joints), with
// the model joint variables q (fixed joints take none).
std::vector<Eigen::Isometry3d> urdf_poses(const UrdfChain& chain, const Eigen::VectorXd& q);

// URDF rpy (roll about x, pitch about y, yaw about z, fixed axes) as a rotation matrix.
Eigen::Matrix3d rotation_from_rpy(const Eigen::Vector3d& rpy);

}  // namespace symoro::twin
