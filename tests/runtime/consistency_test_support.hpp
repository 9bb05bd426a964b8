// Independent checks of physical consistency for the tests (identify/physical_consistency.hpp
// and physical_projection.hpp): pseudo-inertias rebuilt from the parameter names and their
// eigenvalues from Eigen, B s from the generated base_from_standard.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "symoro/identify/physical_consistency.hpp"
#include "symoro/identify/detail/physical_consistency_model.hpp"
#include "test_support.hpp"

namespace symoro::test {

using Eigen::VectorXd;
using symoro::identify::ConsistencyResult;
using symoro::identify::ConsistencyStatus;

// The pseudo-inertia of link `link` from the names in Model::standard_parameters (not from the
// library's index tables): I about the origin, h, m; J = [[tr(I)/2 - I, h], [h', m]].
template <class Model>
Eigen::Matrix4d pseudo_inertia_by_name(const VectorXd& s, int link) {
  Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
  Eigen::Vector3d h = Eigen::Vector3d::Zero();
  double m = 0;
  const char* tensor[3][3] = {{"XX", "XY", "XZ"}, {"XY", "YY", "YZ"}, {"XZ", "YZ", "ZZ"}};
  for (int k = 0; k < Model::ns; ++k) {
    const auto& p = Model::standard_parameters[static_cast<std::size_t>(k)];
    if (p.joint != link) continue;
    const std::string f = p.family;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        if (f == tensor[r][c]) I(r, c) = s(k);
    if (f == "MX") h.x() = s(k);
    if (f == "MY") h.y() = s(k);
    if (f == "MZ") h.z() = s(k);
    if (f == "M") m = s(k);
  }
  Eigen::Matrix4d J;
  J.topLeftCorner<3, 3>() = 0.5 * I.trace() * Eigen::Matrix3d::Identity() - I;
  J.topRightCorner<3, 1>() = h;
  J.bottomLeftCorner<1, 3>() = h.transpose();
  J(3, 3) = m;
  return J;
}

// The smallest eigenvalue over every link's pseudo-inertia, and the smallest IA/FV/FS.
template <class Model>
double smallest_link_eigenvalue(const VectorXd& s) {
  double worst = INFINITY;
  for (int link = 1; link <= Model::nq; ++link) {
    const Eigen::Matrix4d J = pseudo_inertia_by_name<Model>(s, link);
    if (J.isZero(0)) continue;
    worst = std::min(worst, Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(J).eigenvalues()(0));
  }
  return worst;
}
// Friction levels of a variant's effects too (Coulomb, Stribeck: effect_table.hpp's positive rows,
// the rule the solve bounds them by).
template <class Model>
double smallest_drive_parameter(const VectorXd& s) {
  double worst = INFINITY;
  for (int k = 0; k < Model::ns; ++k) {
    const std::string f = Model::standard_parameters[static_cast<std::size_t>(k)].family;
    if (f == "IA" || f == "FV" || f == "FS" || symoro::identify::detail::positive_effect_family(f))
      worst = std::min(worst, s(k));
  }
  return worst;
}

template <class Model>
VectorXd base_of(const VectorXd& s) {
  return Model::base_from_standard(Eigen::Matrix<double, Model::ns, 1>(s));
}

// The checks of a result that claims a consistent set mapping onto phi (the model's own phi).
template <class Model>
void expect_consistent(const ConsistencyResult& r, const VectorXd& phi, double margin) {
  ASSERT_EQ(r.status, ConsistencyStatus::Consistent) << r.message;
  const double tol = 1e-10 * std::max(1.0, phi.cwiseAbs().maxCoeff());
  const VectorXd back = base_of<Model>(r.s);
  EXPECT_LE((back - phi).cwiseAbs().maxCoeff(), tol);
  // A variant: the full base vector too (the fixed combinations at their values), from the
  // rigid part of s (a variant's effect parameters are its last ne entries).
  using Parent = typename Model::Parent;
  const VectorXd full = base_of<Parent>(r.s.head(Parent::ns));
  EXPECT_LE((full - symoro::identify::consistency_target<Model>(phi).head(Parent::np)).cwiseAbs().maxCoeff(), tol);
  EXPECT_GE(smallest_link_eigenvalue<Model>(r.s), margin - 1e-9);
  EXPECT_GE(smallest_drive_parameter<Model>(r.s), -1e-12);
  EXPECT_NEAR(r.lambda_min, smallest_link_eigenvalue<Model>(r.s), 1e-12);
  std::printf("  %s: %s; max|B s - phi| = %.3g, lambda_min = %.4g, prior distance %.4g, %d CSDP solves, %.3f s\n",
              Model::description, r.message.c_str(), (back - phi).cwiseAbs().maxCoeff(), r.lambda_min, r.prior_distance,
              r.solves, r.wall);
}

inline VectorXd perturbed(const VectorXd& s, double fraction, unsigned seed) {
  symoro::test::Random rng(seed);
  VectorXd out = s;
  for (Eigen::Index i = 0; i < s.size(); ++i) out(i) *= 1 + rng.uniform(-fraction, fraction);
  return out;
}

// A consistent link whose inertia about the frame origin is diagonal (the reduced model fixes
// the products of inertia to 0): second moment about the origin diag(m (3 c_i^2 + r_i)), which
// exceeds m c c' (Cauchy-Schwarz), so the second moment about the CoM stays positive definite.
template <class Model>
VectorXd diagonal_consistent_standard(symoro::test::Random& rng) {
  VectorXd s = VectorXd::Zero(Model::ns);
  for (int link = 1; link <= Model::nq; ++link) {
    const double m = rng.uniform(0.5, 2.0);
    const Eigen::Vector3d c = rng.vector<Eigen::Vector3d>(3, -0.15, 0.15);
    Eigen::Vector3d sigma;
    for (int i = 0; i < 3; ++i) sigma(i) = m * (3 * c(i) * c(i) + rng.uniform(0.002, 0.02));
    const Eigen::Vector3d I = sigma.sum() * Eigen::Vector3d::Ones() - sigma;  // XX YY ZZ
    for (int k = 0; k < Model::ns; ++k) {
      const auto& p = Model::standard_parameters[static_cast<std::size_t>(k)];
      if (p.joint != link) continue;
      const std::string f = p.family;
      if (f == "XX") s(k) = I(0);
      if (f == "YY") s(k) = I(1);
      if (f == "ZZ") s(k) = I(2);
      if (f == "MX") s(k) = m * c(0);
      if (f == "MY") s(k) = m * c(1);
      if (f == "MZ") s(k) = m * c(2);
      if (f == "M") s(k) = m;
      if (f == "IA") s(k) = rng.uniform(0.01, 0.05);
      if (f == "FV") s(k) = rng.uniform(0.05, 0.5);
    }
  }
  return s;
}

}  // namespace symoro::test
