// An independent recursive Newton-Euler inverse dynamics in modified Denavit-Hartenberg
// (Khalil-Kleinfinger) frames, written from the textbook equations and the numeric geometry of
// a generated model (Model::frames, Model::gravity). It uses standard (per-link, physical)
// parameters, so it checks the grouping into base parameters as well as the dynamics.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "symoro/mdh.hpp"
#include "symoro/model_info.hpp"

namespace symoro::test {

// Standard parameters of one link, in its own frame: the inertia tensor about the frame origin
// (XX XY XZ; XY YY YZ; XZ YZ ZZ), the first moments (MX MY MZ), the mass, the rotor inertia
// and the viscous and Coulomb friction of its joint.
struct LinkInertia {
  Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
  Eigen::Vector3d ms = Eigen::Vector3d::Zero();
  double m = 0, ia = 0, fv = 0, fs = 0;
};

// ^{ant}T_j of one frame (symoro/mdh.hpp: the textbook transform, shared with the twin).
inline Eigen::Isometry3d frame_transform(const FrameInfo& f, double q) { return mdh_transform(f, q); }

inline double sign_of(double x) { return double((x > 0) - (x < 0)); }

// Joint torques (forces for prismatic joints) of the movable frames, in frame order. Frames
// with sigma = 2 are fixed and take no entry of q, qd, qdd. `gravity` is the vector G of the
// robot description in frame 0; the base is given the acceleration -G.
template <class Frames>
Eigen::VectorXd newton_euler(const Frames& frames, const Eigen::Vector3d& gravity,
                             const std::vector<LinkInertia>& links, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                             const Eigen::VectorXd& qdd) {
  const int n = static_cast<int>(frames.size());
  // Index 0 is the base frame; frame j (1-based) is frames[j - 1].
  std::vector<Eigen::Matrix3d> R(n + 1);  // ^{ant}R_j
  std::vector<Eigen::Vector3d> P(n + 1);  // ^{ant}P_j
  std::vector<Eigen::Vector3d> w(n + 1, Eigen::Vector3d::Zero()), wd = w, vd = w, f = w, nm = w;
  std::vector<int> joint(n + 1, -1);  // index into q of frame j, -1 when fixed
  vd[0] = -gravity;

  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  int k = 0;
  for (int j = 1; j <= n; ++j) {
    const FrameInfo& fr = frames[j - 1];
    const bool moves = fr.sigma != 2;
    if (moves) joint[j] = k++;
    const double qj = moves ? q(joint[j]) : 0.0, qdj = moves ? qd(joint[j]) : 0.0, qddj = moves ? qdd(joint[j]) : 0.0;
    const Eigen::Isometry3d T = frame_transform(fr, qj);
    R[j] = T.linear();
    P[j] = T.translation();
    const int a = fr.ant;
    const Eigen::Matrix3d Rt = R[j].transpose();
    const Eigen::Vector3d wa = Rt * w[a];  // the antecedent's rotation, in frame j
    const bool revolute = fr.sigma == 0, prismatic = fr.sigma == 1;
    w[j] = wa + (revolute ? qdj : 0.0) * z;
    wd[j] = Rt * wd[a] + (revolute ? (qddj * z + wa.cross(qdj * z)).eval() : Eigen::Vector3d::Zero());
    vd[j] = Rt * (vd[a] + wd[a].cross(P[j]) + w[a].cross(w[a].cross(P[j]))) +
            (prismatic ? (qddj * z + 2.0 * wa.cross(qdj * z)).eval() : Eigen::Vector3d::Zero());
    // The link's own inertial force and moment about its frame origin.
    const LinkInertia& L = links[j - 1];
    f[j] = L.m * vd[j] + wd[j].cross(L.ms) + w[j].cross(w[j].cross(L.ms));
    nm[j] = L.J * wd[j] + w[j].cross(L.J * w[j]) + L.ms.cross(vd[j]);
  }

  Eigen::VectorXd tau(k);
  for (int j = n; j >= 1; --j) {
    const FrameInfo& fr = frames[j - 1];
    if (joint[j] >= 0) {
      const int i = joint[j];
      const LinkInertia& L = links[j - 1];
      tau(i) = (fr.sigma == 0 ? nm[j].dot(z) : f[j].dot(z)) + L.ia * qdd(i) + L.fv * qd(i) + L.fs * sign_of(qd(i));
    }
    // Pass the link's wrench to its antecedent (frame 0 needs none).
    const int a = fr.ant;
    const Eigen::Vector3d fa = R[j] * f[j];
    f[a] += fa;
    nm[a] += R[j] * nm[j] + P[j].cross(fa);
  }
  return tau;
}

}  // namespace symoro::test
