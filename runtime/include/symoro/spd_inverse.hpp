// The inverse of a small symmetric positive definite matrix, for generated code (the inertia
// matrix in forward_dynamics_derivatives): an unpivoted LDL^T in plain fixed-size loops, then
// M^-1 = L^-T D^-1 L^-1. At n = 8 Eigen's LDLT::solve(Identity) goes through its blocked
// triangular-solve and GEMM kernels, which cost more than the arithmetic; these loops do not.
// Works for double and for any number type with comparison on its value (ceres::Jet).
#pragma once

#include <Eigen/Core>

namespace symoro {

// Reads M's lower triangle. Returns false, with `min_pivot` the first pivot that is not > 0 and
// `inverse` unset, when M is not positive definite; else true with the smallest pivot.
template <class Scalar, int n>
bool spd_inverse(const Eigen::Matrix<Scalar, n, n>& M, Eigen::Matrix<Scalar, n, n>& inverse, Scalar& min_pivot) {
  Eigen::Matrix<Scalar, n, n> L;  // unit lower triangular; its strict lower part only
  Eigen::Matrix<Scalar, n, 1> D, D_inv;
  for (int j = 0; j < n; ++j) {
    Scalar d = M(j, j);
    for (int k = 0; k < j; ++k) d -= L(j, k) * L(j, k) * D(k);
    if (j == 0 || d < min_pivot) min_pivot = d;
    if (!(d > Scalar(0))) return false;
    D(j) = d;
    D_inv(j) = Scalar(1) / d;
    for (int i = j + 1; i < n; ++i) {
      Scalar s = M(i, j);
      for (int k = 0; k < j; ++k) s -= L(i, k) * L(j, k) * D(k);
      L(i, j) = s * D_inv(j);
    }
  }
  // X = L^-1 (unit lower triangular), column by column.
  Eigen::Matrix<Scalar, n, n> X;
  X.setZero();
  for (int c = 0; c < n; ++c) {
    X(c, c) = Scalar(1);
    for (int i = c + 1; i < n; ++i) {
      Scalar s = -L(i, c);
      for (int k = c + 1; k < i; ++k) s -= L(i, k) * X(k, c);
      X(i, c) = s;
    }
  }
  // M^-1 = X^T D^-1 X, symmetric: the lower triangle, mirrored.
  for (int i = 0; i < n; ++i)
    for (int j = 0; j <= i; ++j) {
      Scalar s(0);
      for (int k = i; k < n; ++k) s += X(k, i) * X(k, j) * D_inv(k);
      inverse(i, j) = s;
      inverse(j, i) = s;
    }
  return true;
}

}  // namespace symoro
