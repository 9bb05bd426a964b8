// The robot's models on the expression graph: the frames' transforms (modified DH), the
// inverse dynamics by the recursive Newton-Euler algorithm, the direct geometric model and the
// Jacobian of the last frame.
#pragma once

#include <array>
#include <vector>

#include "description.hpp"

namespace symoro::codegen::modeling {

using Vec3 = std::array<NodeId, 3>;
using Mat3 = std::array<Vec3, 3>;  // rows

// x_ant = R x_j + p: frame j in its antecedent.
struct Transform {
  Mat3 R;
  Vec3 p;
};

// ant T j = Rz(gamma) Tz(b) Rx(alpha) Tx(d) Rz(theta) Tz(r), with theta and r as given.
Transform frame_transform(ExprGraph& g, const JointDescription& j, NodeId theta, NodeId r);
// The same with the joint's own variable: theta for a revolute joint, r for a prismatic one.
Transform joint_transform(ExprGraph& g, const JointDescription& j);

// tau = ID(q, qd, qdd) with the given link parameters (standard or grouped): rigid bodies,
// rotor inertia IA qdd, viscous FV qd and Coulomb FS sign(qd) friction. One node per joint.
std::vector<NodeId> inverse_dynamics(ExprGraph& g, const Description& d, const std::vector<LinkParameters>& links);

// 0 T f of frame f (1..n): a 3 x 4 [R p], rows of nodes.
std::array<std::array<NodeId, 4>, 3> frame_pose(ExprGraph& g, const Description& d, int f);

// The 6 x n Jacobian of frame f's origin, projected in frame 0: rows vx vy vz wx wy wz.
std::vector<std::vector<NodeId>> frame_jacobian(ExprGraph& g, const Description& d, int f);

// Small vector algebra on nodes.
Vec3 add(ExprGraph& g, const Vec3& a, const Vec3& b);
Vec3 sub(ExprGraph& g, const Vec3& a, const Vec3& b);
Vec3 scale(ExprGraph& g, NodeId s, const Vec3& a);
Vec3 cross(ExprGraph& g, const Vec3& a, const Vec3& b);
NodeId dot(ExprGraph& g, const Vec3& a, const Vec3& b);
Vec3 times(ExprGraph& g, const Mat3& R, const Vec3& v);            // R v
Vec3 transpose_times(ExprGraph& g, const Mat3& R, const Vec3& v);  // R^T v
Mat3 times(ExprGraph& g, const Mat3& A, const Mat3& B);

}  // namespace symoro::codegen::modeling
