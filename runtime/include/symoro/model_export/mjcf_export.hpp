// A robot model with a standard parameter vector as a MuJoCo model (MJCF; dynid export --mjcf).
// The same frames as the URDF export (urdf_export.hpp): one body per model frame, nested by
// antecedent, whose pos/quat are the frame's modified-DH transform at q = 0, so that each body
// frame IS the model frame, with a hinge (slide) joint on its z axis at its origin, so that
// MuJoCo's qpos is the model's q. Per body: <inertial> with mass, CoM and the full inertia about
// the CoM (fullinertia) from XX..ZZ, MX MY MZ, M. Per joint: armature = IA (the rotor inertia URDF
// cannot hold), damping = FV, frictionloss = FS, range = the joint's limits; a motor per joint
// whose force is limited to its effort limit. Gravity is the model's (frame 0 = MuJoCo's world).
//
// MuJoCo's dry friction (frictionloss) is a constraint solved with the rest, not the model's
// FS sign(qd): equal in effect at speed, not in every sample, so a comparison of inverse
// dynamics leaves it out (the tests do). Effect parameters (offsets, smooth Coulomb) have no
// MJCF counterpart, and a model that has them is not exported (export_model refuses it).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "symoro/model_export/urdf_export.hpp"

namespace symoro::model_export {

// A body to attach (a payload): its inertial in the frame `pose` places on model frame `frame`.
struct MjcfAttachment {
  std::string name;
  int frame = 0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  UrdfInertial inertial;
};

// Throws std::invalid_argument on an inconsistent description, a movable body MuJoCo would
// refuse (mass and every principal moment 0 with no massive body below it, or a principal
// moment negative, or moments that break A + B >= C): the message names the frame.
std::string mjcf_text(const UrdfDescription& d, const Eigen::Vector3d& gravity,
                      const std::vector<MjcfAttachment>& attachments = {});

// MuJoCo's quat (w x y z) of a rotation.
Eigen::Vector4d mjcf_quat(const Eigen::Matrix3d& R);

}  // namespace symoro::model_export
