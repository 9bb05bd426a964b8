// InertiaFunction for a generated Model (Model::inertia, Model::inertia_basis): values in
// double, dM/dq from the generated inertia_derivatives (differentiated on the expression graph),
// d2M/dq2 from the same function in ceres::Jet<double, 1>, seeded on one q_l at a time.
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
  using Jet = ceres::Jet<double, 1>;  // one direction of q at a time

  int joints() const override { return n; }
  int parameters() const override { return Model::np; }

  void inertia(const Eigen::VectorXd& q, const Eigen::VectorXd& phi, Eigen::MatrixXd& M) const override {
    check(q, phi);
    Model::inertia(q, phi, M);
  }

  void basis(const Eigen::VectorXd& q, Eigen::MatrixXd& constant, std::vector<Eigen::MatrixXd>& linear) const override {
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
    // Generated, differentiated on the expression graph (inertia_derivatives.hpp); kept off a
    // worker thread's stack like the basis.
    auto d = std::make_unique<typename Model::template InertiaDerivatives<double>>();
    Model::inertia_derivatives(q, phi, *d);
    M = d->M;
    dM_dq.assign(d->dq.begin(), d->dq.end());
  }

  bool inertia_second_derivatives(const Eigen::VectorXd& q, const Eigen::VectorXd& phi, Eigen::MatrixXd& M,
                                  std::vector<Eigen::MatrixXd>& dM_dq,
                                  std::vector<Eigen::MatrixXd>& d2M_dq2) const override {
    check(q, phi);
    // The generated first derivatives in one-direction Jets, seeded on q_l for each l: their
    // derivative parts are d2M / dq_k dq_l. The same arithmetic, entry by entry, as one Jet over
    // all of q, for a third of the compilation (a Jet<double, nq> instantiation of the crane_x7's
    // inertia_derivatives took 25 s of the model's unit).
    M.resize(n, n);
    dM_dq.assign(n, Eigen::MatrixXd(n, n));
    d2M_dq2.assign(n * n, Eigen::MatrixXd(n, n));
    auto d = std::make_unique<typename Model::template InertiaDerivatives<Jet>>();
    Eigen::Matrix<Jet, n, 1> qj;
    for (int l = 0; l < n; ++l) {
      for (int k = 0; k < n; ++k) qj(k) = Jet(q(k));
      qj(l).v(0) = 1;
      Model::inertia_derivatives(qj, phi, *d);
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          if (l == 0) M(i, j) = d->M(i, j).a;
          for (int k = 0; k < n; ++k) {
            const Jet& e = d->dq[k](i, j);
            if (l == 0) dM_dq[k](i, j) = e.a;
            d2M_dq2[k * n + l](i, j) = e.v(0);
          }
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
