// Derivatives two ways: forward-mode ceres::Jet through the generated code, and central finite
// differences of its double version. Both are laid out as (flattened output) x (input) matrices,
// or, for a Jet along one direction v, as the flattened output's derivative (the Jacobian times v).
#pragma once

#include <type_traits>

#include <Eigen/Core>
#include <ceres/jet.h>

namespace symoro::test {

// x as Jets whose derivative part is the identity: x(i) carries d/dx_i.
template <int N, class Derived>
Eigen::Matrix<ceres::Jet<double, N>, Derived::RowsAtCompileTime, 1> seeded(const Eigen::MatrixBase<Derived>& x) {
  static_assert(Derived::RowsAtCompileTime == N, "seed a vector of N entries");
  Eigen::Matrix<ceres::Jet<double, N>, N, 1> out;
  for (int i = 0; i < N; ++i) out(i) = ceres::Jet<double, N>(x(i), i);
  return out;
}

// The one Jet type of the robot tests: a directional derivative. A generated function is
// instantiated per scalar type and per argument type, and its instantiations in Jet<double, nq>
// and Jet<double, np> made the test units take minutes (issue 27); a Jet with one derivative
// carries d/dt f(x + t v), which is the Jacobian times v: against the reference Jacobian times a
// random v it detects any wrong entry with probability 1.
using Dual = ceres::Jet<double, 1>;

// x as Jets with derivative part v: the derivative along v. Every argument of a generated function
// called in Jets goes through jet(), so that each function has one Jet instantiation.
template <class X, class V>
Eigen::Matrix<Dual, X::RowsAtCompileTime, 1> jet(const Eigen::MatrixBase<X>& x, const Eigen::MatrixBase<V>& v) {
  static_assert(X::ColsAtCompileTime == 1 && V::ColsAtCompileTime == 1, "vectors");
  eigen_assert(x.size() == v.size());
  Eigen::Matrix<Dual, X::RowsAtCompileTime, 1> out(x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    out(i).a = x(i);
    out(i).v(0) = v(i);
  }
  return out;
}
// x as Jets with zero derivative part: a constant of the derivative.
template <class X>
Eigen::Matrix<Dual, X::RowsAtCompileTime, 1> jet(const Eigen::MatrixBase<X>& x) {
  return jet(x, X::PlainObject::Zero(x.size()));
}

// Derivative part of a matrix of Duals, in its shape.
template <class Derived>
Eigen::MatrixXd derivative(const Eigen::MatrixBase<Derived>& m) {
  static_assert(std::is_same_v<typename Derived::Scalar, Dual>, "a matrix of Duals");
  Eigen::MatrixXd out(m.rows(), m.cols());
  for (Eigen::Index j = 0; j < m.cols(); ++j)
    for (Eigen::Index i = 0; i < m.rows(); ++i) out(i, j) = m(i, j).v(0);
  return out;
}
// The same flattened in column-major order: the layout of finite_difference_jacobian's rows, so
// that it compares with finite_difference_jacobian(f, x, h) * v.
template <class Derived>
Eigen::VectorXd flat_derivative(const Eigen::MatrixBase<Derived>& m) {
  const Eigen::MatrixXd d = derivative(m);
  return Eigen::Map<const Eigen::VectorXd>(d.data(), d.size());
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
