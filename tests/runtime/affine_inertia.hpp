// M(q; phi) = C + sum_i phi_i L_i with no dependence on q, and the Frobenius parameterization of
// a symmetric matrix: the SDP projection's closed-form cases (test_identify_sdp*.cpp).
#pragma once

#include <cmath>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "symoro/identify/inertia_function.hpp"

namespace symoro::test {

// M(q; phi) = C + sum_i phi_i L_i with no dependence on q: the closed-form cases.
class AffineInertia : public identify::InertiaFunction {
 public:
  AffineInertia(Eigen::MatrixXd constant, std::vector<Eigen::MatrixXd> linear)
      : constant_(std::move(constant)), linear_(std::move(linear)) {}
  int joints() const override { return static_cast<int>(constant_.rows()); }
  int parameters() const override { return static_cast<int>(linear_.size()); }
  void inertia(const Eigen::VectorXd&, const Eigen::VectorXd& phi, Eigen::MatrixXd& M) const override {
    M = constant_;
    for (int i = 0; i < parameters(); ++i) M += phi(i) * linear_[i];
  }
  void basis(const Eigen::VectorXd&, Eigen::MatrixXd& constant, std::vector<Eigen::MatrixXd>& linear) const override {
    constant = constant_;
    linear = linear_;
  }
  void inertia_derivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& phi, Eigen::MatrixXd& M,
                           std::vector<Eigen::MatrixXd>& dM_dq) const override {
    inertia(q, phi, M);
    dM_dq.assign(joints(), Eigen::MatrixXd::Zero(joints(), joints()));
  }

 private:
  Eigen::MatrixXd constant_;
  std::vector<Eigen::MatrixXd> linear_;
};

inline Eigen::MatrixXd unit(int n, int i, int j) {
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(n, n);
  E(i, j) = E(j, i) = 1;
  return E;
}

// phi -> the symmetric n x n matrix whose Frobenius norm is |phi| (off-diagonal entries
// phi_k / sqrt(2)), so that the projection in phi is the Frobenius projection of the matrix.
inline AffineInertia frobenius_model(int n) {
  std::vector<Eigen::MatrixXd> L;
  for (int i = 0; i < n; ++i)
    for (int j = i; j < n; ++j) L.push_back(i == j ? unit(n, i, i) : unit(n, i, j) / std::sqrt(2.0));
  return AffineInertia(Eigen::MatrixXd::Zero(n, n), L);
}

inline Eigen::VectorXd frobenius_params(const Eigen::MatrixXd& M) {
  const int n = static_cast<int>(M.rows());
  Eigen::VectorXd p(n * (n + 1) / 2);
  int k = 0;
  for (int i = 0; i < n; ++i)
    for (int j = i; j < n; ++j) p(k++) = i == j ? M(i, i) : std::sqrt(2.0) * M(i, j);
  return p;
}

// The Frobenius-nearest matrix with every eigenvalue >= eps: clip the eigenvalues.
inline Eigen::MatrixXd clip_eigenvalues(const Eigen::MatrixXd& M, double eps) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(M);
  const Eigen::VectorXd l = es.eigenvalues().cwiseMax(eps);
  return es.eigenvectors() * l.asDiagonal() * es.eigenvectors().transpose();
}

}  // namespace symoro::test
