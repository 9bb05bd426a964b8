// InertiaFunction for a generated Model (Model::inertia, Model::inertia_basis): values in
// double, dM/dq in ceres::Jet<double, nq>, d2M/dq2 in a small second-order forward-mode number
// (ceres Jets do not nest through the generated code: it builds scalars from double and int).
#pragma once

#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <ceres/jet.h>

#include "symoro/identify/inertia_function.hpp"

namespace symoro::identify {
namespace detail {

// A value with its gradient and Hessian in N seeded variables: enough arithmetic (+ - *, sin,
// cos, comparisons on the value) for the generated inertia code, which divides nowhere.
template <int N>
struct SecondOrder {
  using Gradient = Eigen::Matrix<double, N, 1>;
  using Hessian = Eigen::Matrix<double, N, N>;
  double a = 0;
  Gradient g = Gradient::Zero();
  Hessian h = Hessian::Zero();

  SecondOrder() = default;
  SecondOrder(double value) : a(value) {}  // NOLINT: constants in generated code convert implicitly
  // The variable k of N at `value`.
  static SecondOrder variable(double value, int k) {
    SecondOrder x(value);
    x.g(k) = 1;
    return x;
  }

  SecondOrder& operator+=(const SecondOrder& y) {
    a += y.a;
    g += y.g;
    h += y.h;
    return *this;
  }
  SecondOrder& operator-=(const SecondOrder& y) {
    a -= y.a;
    g -= y.g;
    h -= y.h;
    return *this;
  }
  SecondOrder& operator*=(const SecondOrder& y) { return *this = *this * y; }

  // f(x) from f(a), f'(a), f''(a).
  SecondOrder chain(double f, double d1, double d2) const {
    SecondOrder r(f);
    r.g = d1 * g;
    r.h = d1 * h + d2 * g * g.transpose();
    return r;
  }

  friend SecondOrder operator+(const SecondOrder& x) { return x; }
  friend SecondOrder operator-(const SecondOrder& x) { return x * -1.0; }
  friend SecondOrder operator+(SecondOrder x, const SecondOrder& y) { return x += y; }
  friend SecondOrder operator-(SecondOrder x, const SecondOrder& y) { return x -= y; }
  friend SecondOrder operator+(SecondOrder x, double s) {
    x.a += s;
    return x;
  }
  friend SecondOrder operator+(double s, const SecondOrder& x) { return x + s; }
  friend SecondOrder operator-(const SecondOrder& x, double s) { return x + (-s); }
  friend SecondOrder operator-(double s, const SecondOrder& x) { return s + (-x); }
  friend SecondOrder operator*(const SecondOrder& x, const SecondOrder& y) {
    SecondOrder r(x.a * y.a);
    r.g = x.a * y.g + y.a * x.g;
    const Hessian cross = x.g * y.g.transpose();
    r.h = x.a * y.h + y.a * x.h + cross + cross.transpose();
    return r;
  }
  friend SecondOrder operator*(SecondOrder x, double s) {
    x.a *= s;
    x.g *= s;
    x.h *= s;
    return x;
  }
  friend SecondOrder operator*(double s, SecondOrder x) { return x * s; }

  friend SecondOrder sin(const SecondOrder& x) {
    const double s = std::sin(x.a), c = std::cos(x.a);
    return x.chain(s, c, -s);
  }
  friend SecondOrder cos(const SecondOrder& x) {
    const double s = std::sin(x.a), c = std::cos(x.a);
    return x.chain(c, -s, -c);
  }

  friend bool operator<(const SecondOrder& x, const SecondOrder& y) { return x.a < y.a; }
  friend bool operator>(const SecondOrder& x, const SecondOrder& y) { return x.a > y.a; }
  friend bool operator<=(const SecondOrder& x, const SecondOrder& y) { return x.a <= y.a; }
  friend bool operator>=(const SecondOrder& x, const SecondOrder& y) { return x.a >= y.a; }
  friend bool operator==(const SecondOrder& x, const SecondOrder& y) { return x.a == y.a; }
  friend bool operator!=(const SecondOrder& x, const SecondOrder& y) { return x.a != y.a; }
};

inline void check_size(const char* what, Eigen::Index size, int expected) {
  if (size != expected)
    throw std::invalid_argument(std::string("InertiaFunction: ") + what + " has " + std::to_string(size) +
                                " entries, expected " + std::to_string(expected));
}

}  // namespace detail

template <class Model>
class ModelInertiaFunction final : public InertiaFunction {
 public:
  static constexpr int n = Model::nq;
  using Jet = ceres::Jet<double, n>;
  using Second = detail::SecondOrder<n>;

  int joints() const override { return n; }
  int parameters() const override { return Model::np; }

  void inertia(const Eigen::VectorXd& q, const Eigen::VectorXd& phi, Eigen::MatrixXd& M) const override {
    check(q, phi);
    Model::inertia(q, phi, M);
  }

  void basis(const Eigen::VectorXd& q, Eigen::MatrixXd& constant,
             std::vector<Eigen::MatrixXd>& linear) const override {
    detail::check_size("q", q.size(), n);
    // np fixed n x n matrices (33 kB for the full CRANE-X7): kept off a worker thread's stack.
    auto b = std::make_unique<typename Model::template InertiaBasis<double>>();
    Model::inertia_basis(q, *b);
    constant = b->constant;
    linear.assign(b->linear.begin(), b->linear.end());
  }

  void inertia_derivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& phi, Eigen::MatrixXd& M,
                           std::vector<Eigen::MatrixXd>& dM_dq) const override {
    check(q, phi);
    Eigen::Matrix<Jet, n, 1> qj;
    for (int k = 0; k < n; ++k) qj(k) = Jet(q(k), k);
    // Dynamic output: fixed-size Jet matrices hit Eigen's stack limit for large models.
    Eigen::Matrix<Jet, Eigen::Dynamic, Eigen::Dynamic> Mj;
    Model::inertia(qj, phi, Mj);
    M.resize(n, n);
    dM_dq.assign(n, Eigen::MatrixXd(n, n));
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        M(i, j) = Mj(i, j).a;
        for (int k = 0; k < n; ++k) dM_dq[k](i, j) = Mj(i, j).v(k);
      }
  }

  bool inertia_second_derivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& phi, Eigen::MatrixXd& M,
                                  std::vector<Eigen::MatrixXd>& dM_dq,
                                  std::vector<Eigen::MatrixXd>& d2M_dq2) const override {
    check(q, phi);
    Eigen::Matrix<Second, Eigen::Dynamic, 1> qs(n);
    for (int k = 0; k < n; ++k) qs(k) = Second::variable(q(k), k);
    Eigen::Matrix<Second, Eigen::Dynamic, Eigen::Dynamic> Ms;
    Model::inertia(qs, phi, Ms);
    M.resize(n, n);
    dM_dq.assign(n, Eigen::MatrixXd(n, n));
    d2M_dq2.assign(n * n, Eigen::MatrixXd(n, n));
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const Second& e = Ms(i, j);
        M(i, j) = e.a;
        for (int k = 0; k < n; ++k) {
          dM_dq[k](i, j) = e.g(k);
          for (int l = 0; l < n; ++l) d2M_dq2[k * n + l](i, j) = e.h(k, l);
        }
      }
    return true;
  }

 private:
  static void check(const Eigen::VectorXd& q, const Eigen::VectorXd& phi) {
    detail::check_size("q", q.size(), n);
    detail::check_size("phi", phi.size(), Model::np);
  }
};

template <class Model>
std::unique_ptr<InertiaFunction> make_inertia_function() {
  return std::make_unique<ModelInertiaFunction<Model>>();
}

}  // namespace symoro::identify

// Eigen needs to know SecondOrder is a real, non-integer number to hold it in matrices.
namespace Eigen {
template <int N>
struct NumTraits<symoro::identify::detail::SecondOrder<N>> : NumTraits<double> {
  using Real = symoro::identify::detail::SecondOrder<N>;
  using NonInteger = Real;
  using Nested = Real;
  using Literal = Real;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = 1 + N + N * N,
    AddCost = 1 + N + N * N,
    MulCost = 3 * (1 + N + N * N),
  };
};
}  // namespace Eigen
