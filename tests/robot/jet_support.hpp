// Derivatives two ways: forward-mode ceres::Jet through the generated code, and central finite
// differences of its double version. Both are laid out as (flattened output) x (input) matrices.
#pragma once

#include <Eigen/Core>
#include <ceres/jet.h>

namespace symoro::test {

// x as Jets whose derivative part is the identity: x(i) carries d/dx_i.
template <int N, class Derived>
Eigen::Matrix<ceres::Jet<double, N>, Derived::RowsAtCompileTime, 1> seeded(
    const Eigen::MatrixBase<Derived>& x) {
  static_assert(Derived::RowsAtCompileTime == N, "seed a vector of N entries");
  Eigen::Matrix<ceres::Jet<double, N>, N, 1> out;
  for (int i = 0; i < N; ++i) out(i) = ceres::Jet<double, N>(x(i), i);
  return out;
}

// Value part of a matrix of Jets.
template <class Derived>
Eigen::MatrixXd values(const Eigen::MatrixBase<Derived>& m) {
  return m.unaryExpr([](const auto& j) { return j.a; }).template cast<double>();
}

// d vec(m) / d x: row r of the result is the derivative part of the r-th entry of m in
// column-major order.
template <class Derived>
Eigen::MatrixXd jet_jacobian(const Eigen::MatrixBase<Derived>& m) {
  using Jet = typename Derived::Scalar;
  constexpr int N = decltype(Jet::v)::RowsAtCompileTime;
  const Eigen::Index n = m.size();
  Eigen::MatrixXd out(n, N);
  for (Eigen::Index k = 0; k < n; ++k) out.row(k) = m(k % m.rows(), k / m.rows()).v.transpose();
  return out;
}

// Central differences of f (a vector -> any Eigen object function) around x with step h.
template <class F, class Vector>
Eigen::MatrixXd finite_difference_jacobian(const F& f, const Vector& x, double h) {
  Eigen::MatrixXd out;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    Vector plus = x, minus = x;
    plus(i) += h;
    minus(i) -= h;
    const Eigen::MatrixXd d = (Eigen::MatrixXd(f(plus)) - Eigen::MatrixXd(f(minus))) / (2 * h);
    if (i == 0) out.resize(d.size(), x.size());
    out.col(i) = Eigen::Map<const Eigen::VectorXd>(d.data(), d.size());
  }
  return out;
}

}  // namespace symoro::test
