// A rigid payload's (or tool's) 10 inertial parameters and the conversions between their forms:
//   - mass m, centre of mass c and the inertia I_c about the centre of mass, in a frame F
//     (what a user and a controller's load settings give);
//   - the standard parameters of a link, in its frame L, as OpenSYMORO writes them:
//     XX XY XZ YY YZ ZZ (the inertia tensor about L's origin, XY = I(0, 1) = -int x y dm),
//     MX MY MZ (m c) and M, where identification is linear;
//   - the pseudo-inertia J = [[Sigma, m c], [m c', m]], Sigma = int r r' dm about the origin
//     (Wensing, Kim, Slotine 2017): the body is physically realizable exactly when J >= 0, and
//     strictly so (a body with volume) when J > 0.
#pragma once

#include <array>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace symoro::payload {

// The standard parameters' order (payload_standard_names) and their count.
inline constexpr int kInertialParameters = 10;
using StandardVector = Eigen::Matrix<double, kInertialParameters, 1>;
const std::array<const char*, kInertialParameters>& payload_standard_names();  // XX ... M

struct PayloadInertial {
  double mass = 0;                                    // kg
  Eigen::Vector3d com = Eigen::Vector3d::Zero();      // m, in the frame
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  // kg m^2 about the CoM, the frame's axes

  // The link's standard parameters when the payload, given in frame F, rides on a link whose
  // frame L holds F at `F_in_L`.
  StandardVector standard(const Eigen::Isometry3d& F_in_L = Eigen::Isometry3d::Identity()) const;
  // The payload in frame F from a link's standard parameters (mass > 0; else com and inertia 0).
  static PayloadInertial from_standard(const StandardVector& s,
                                       const Eigen::Isometry3d& F_in_L = Eigen::Isometry3d::Identity());
  // The same body expressed in another frame G that holds this frame at `this_in_G`.
  PayloadInertial expressed_in(const Eigen::Isometry3d& this_in_G) const;
};

// The pseudo-inertia of standard parameters (about their frame's origin).
Eigen::Matrix4d pseudo_inertia(const StandardVector& s);
// The standard parameters of a pseudo-inertia.
StandardVector standard_of_pseudo_inertia(const Eigen::Matrix4d& J);
// The smallest eigenvalue of J relative to its largest (1 a sphere's shell; <= 0 no body).
double consistency_margin(const StandardVector& s);

// The inertia's principal moments (ascending) and axes (columns, a right-handed rotation).
void principal_axes(const Eigen::Matrix3d& inertia, Eigen::Vector3d& moments, Eigen::Matrix3d& axes);

}  // namespace symoro::payload
