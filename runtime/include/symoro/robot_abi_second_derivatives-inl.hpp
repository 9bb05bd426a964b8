// The inertia matrix's second derivatives along q for the robot library's C ABI
// (symoro/robot_abi.h), in their own unit per model (symoroc build): Jets over the generated first
// derivatives are half of a model's compile time, and compile beside the other half.
#pragma once

#include <Eigen/Core>
#include <ceres/jet.h>

#include "symoro/robot_abi_export-inl.hpp"

namespace symoro::abi_export {

// The generated first derivatives in one-direction Jets seeded on q_l for each l: their
// derivative parts are d2M / dq_k dq_l (block k * nq + l), M and dM/dq_k their values.
template <class Model>
void inertia_second_derivatives(const double* q, const double* phi, double* m, double* dm, double* d2m) {
  constexpr int n = Model::nq, np = Model::np;
  using Jet = ceres::Jet<double, 1>;
  thread_local typename Model::template InertiaDerivatives<Jet> d;
  const Eigen::Map<const Eigen::Matrix<double, np, 1>> p(phi);
  Eigen::Matrix<Jet, n, 1> qj;
  for (int l = 0; l < n; ++l) {
    for (int k = 0; k < n; ++k) qj(k) = Jet(q[k]);
    qj(l).v(0) = 1;
    Model::inertia_derivatives(qj, p, d);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        if (l == 0) m[i + j * n] = d.M(i, j).a;
        for (int k = 0; k < n; ++k) {
          const Jet& e = d.dq[k](i, j);
          if (l == 0) dm[k * n * n + i + j * n] = e.a;
          d2m[(k * n + l) * n * n + i + j * n] = e.v(0);
        }
      }
  }
}

}  // namespace symoro::abi_export
