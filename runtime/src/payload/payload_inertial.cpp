#include "symoro/payload/payload_inertial.hpp"

#include <Eigen/Eigenvalues>

namespace symoro::payload {

namespace {

Eigen::Matrix3d tensor_of(const StandardVector& s) {
  Eigen::Matrix3d I;
  I << s(0), s(1), s(2), s(1), s(3), s(4), s(2), s(4), s(5);
  return I;
}

// The parallel-axis term: inertia of a point mass m at c about the origin.
Eigen::Matrix3d point_inertia(double m, const Eigen::Vector3d& c) {
  return m * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
}

}  // namespace

const std::array<const char*, kInertialParameters>& payload_standard_names() {
  static const std::array<const char*, kInertialParameters> names{
      {"XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M"}};
  return names;
}

StandardVector PayloadInertial::standard(const Eigen::Isometry3d& F_in_L) const {
  const Eigen::Matrix3d R = F_in_L.linear();
  const Eigen::Vector3d c = F_in_L * com;
  const Eigen::Matrix3d I = R * inertia * R.transpose() + point_inertia(mass, c);
  StandardVector s;
  s << I(0, 0), I(0, 1), I(0, 2), I(1, 1), I(1, 2), I(2, 2), mass * c, mass;
  return s;
}

PayloadInertial PayloadInertial::from_standard(const StandardVector& s, const Eigen::Isometry3d& F_in_L) {
  PayloadInertial p;
  p.mass = s(9);
  if (!(p.mass > 0)) return p;
  const Eigen::Vector3d c = s.segment<3>(6) / p.mass;
  const Eigen::Matrix3d Ic = tensor_of(s) - point_inertia(p.mass, c);
  const Eigen::Matrix3d R = F_in_L.linear();
  p.com = F_in_L.inverse() * c;
  p.inertia = R.transpose() * Ic * R;
  p.inertia = (p.inertia + p.inertia.transpose()) / 2;
  return p;
}

PayloadInertial PayloadInertial::expressed_in(const Eigen::Isometry3d& this_in_G) const {
  PayloadInertial p = *this;
  p.com = this_in_G * com;
  p.inertia = this_in_G.linear() * inertia * this_in_G.linear().transpose();
  return p;
}

Eigen::Matrix4d pseudo_inertia(const StandardVector& s) {
  const Eigen::Matrix3d I = tensor_of(s);
  Eigen::Matrix4d J;
  J.topLeftCorner<3, 3>() = 0.5 * I.trace() * Eigen::Matrix3d::Identity() - I;
  J.topRightCorner<3, 1>() = s.segment<3>(6);
  J.bottomLeftCorner<1, 3>() = s.segment<3>(6).transpose();
  J(3, 3) = s(9);
  return J;
}

StandardVector standard_of_pseudo_inertia(const Eigen::Matrix4d& J) {
  const Eigen::Matrix3d S = (J.topLeftCorner<3, 3>() + J.topLeftCorner<3, 3>().transpose()) / 2;
  const Eigen::Matrix3d I = S.trace() * Eigen::Matrix3d::Identity() - S;
  StandardVector s;
  s << I(0, 0), I(0, 1), I(0, 2), I(1, 1), I(1, 2), I(2, 2), J(0, 3), J(1, 3), J(2, 3), J(3, 3);
  return s;
}

double consistency_margin(const StandardVector& s) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> e(pseudo_inertia(s));
  const double top = e.eigenvalues().cwiseAbs().maxCoeff();
  return top > 0 ? e.eigenvalues()(0) / top : 0;
}

void principal_axes(const Eigen::Matrix3d& inertia, Eigen::Vector3d& moments, Eigen::Matrix3d& axes) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> e((inertia + inertia.transpose()) / 2);
  moments = e.eigenvalues();
  axes = e.eigenvectors();
  if (axes.determinant() < 0) axes.col(2) = -axes.col(2);
}

}  // namespace symoro::payload
