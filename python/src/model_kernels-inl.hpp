// model_kernels<Model>(): the batch loops of one generated model (included by the per-model
// units that CMake writes from robot_unit.cpp.in).
#pragma once

#include <limits>
#include <tuple>
#include <vector>

#include <Eigen/Core>

#include "model_kernels.hpp"
#include "symoro/identify/identification_model.hpp"

namespace symoro::python {

namespace detail {

// A fixed-size matrix in C order (a vector in Eigen's only order for vectors).
template <int R, int C>
using RowMajorMatrix = Eigen::Matrix<double, R, C, (C == 1 && R != 1) ? Eigen::ColMajor : Eigen::RowMajor>;

template <int R, int C, class M>
void put(double* out, const M& m) {
  Eigen::Map<RowMajorMatrix<R, C>> dst(out);
  dst = m;
}

template <int N>
Eigen::Map<const Eigen::Matrix<double, N, 1>> vec(const double* p) {
  return Eigen::Map<const Eigen::Matrix<double, N, 1>>(p);
}

template <class Model>
struct Kernels {
  static constexpr int nq = Model::nq, np = Model::np, ns = Model::ns;
  using Vq = Eigen::Matrix<double, nq, 1>;
  using Mqq = Eigen::Matrix<double, nq, nq>;

  static void regressor(const double* q, const double* qd, const double* qdd, double* w, Batch b) {
    Eigen::Matrix<double, nq, np> m;
    for (std::ptrdiff_t k = 0; k < b.n; ++k) {
      Model::regressor(vec<nq>(q + k * nq), vec<nq>(qd + k * nq), vec<nq>(qdd + k * nq), m);
      put<nq, np>(w + k * nq * np, m);
    }
  }
  static void inverse_dynamics(const double* q, const double* qd, const double* qdd, const double* phi, double* tau,
                               Batch b) {
    Vq t;
    for (std::ptrdiff_t k = 0; k < b.n; ++k) {
      Model::inverse_dynamics(vec<nq>(q + k * nq), vec<nq>(qd + k * nq), vec<nq>(qdd + k * nq),
                              vec<np>(phi + k * b.phi_stride), t);
      put<nq, 1>(tau + k * nq, t);
    }
  }
  static void inertia(const double* q, const double* phi, double* out, Batch b) {
    Mqq m;
    for (std::ptrdiff_t k = 0; k < b.n; ++k) {
      Model::inertia(vec<nq>(q + k * nq), vec<np>(phi + k * b.phi_stride), m);
      put<nq, nq>(out + k * nq * nq, m);
    }
  }
  static void nonlinear_effects(const double* q, const double* qd, const double* phi, double* h, Batch b) {
    Vq t;
    for (std::ptrdiff_t k = 0; k < b.n; ++k) {
      Model::nonlinear_effects(vec<nq>(q + k * nq), vec<nq>(qd + k * nq), vec<np>(phi + k * b.phi_stride), t);
      put<nq, 1>(h + k * nq, t);
    }
  }
  static void forward_dynamics(const double* q, const double* qd, const double* tau, const double* phi, double* qdd,
                               Batch b) {
    Vq a;
    for (std::ptrdiff_t k = 0; k < b.n; ++k) {
      Model::forward_dynamics(vec<nq>(q + k * nq), vec<nq>(qd + k * nq), vec<nq>(tau + k * nq),
                              vec<np>(phi + k * b.phi_stride), a);
      put<nq, 1>(qdd + k * nq, a);
    }
  }
  static void inverse_dynamics_derivatives(const double* q, const double* qd, const double* qdd, const double* phi,
                                           double* tau, double* dq, double* dqd, Batch b) {
    typename Model::template InverseDynamicsDerivatives<double> d;
    for (std::ptrdiff_t k = 0; k < b.n; ++k) {
      Model::inverse_dynamics_derivatives(vec<nq>(q + k * nq), vec<nq>(qd + k * nq), vec<nq>(qdd + k * nq),
                                          vec<np>(phi + k * b.phi_stride), d);
      put<nq, 1>(tau + k * nq, d.tau);
      put<nq, nq>(dq + k * nq * nq, d.dq);
      put<nq, nq>(dqd + k * nq * nq, d.dqd);
    }
  }
  static void forward_dynamics_derivatives(const double* q, const double* qd, const double* tau, const double* phi,
                                           double* qdd, double* dq, double* dqd, double* dtau, double* dphi,
                                           double* min_pivot, Batch b) {
    typename Model::template ForwardDynamicsDerivatives<double> d;
    for (std::ptrdiff_t k = 0; k < b.n; ++k) {
      if (!Model::forward_dynamics_derivatives(vec<nq>(q + k * nq), vec<nq>(qd + k * nq), vec<nq>(tau + k * nq),
                                               vec<np>(phi + k * b.phi_stride), d)) {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        d.qdd.setConstant(nan);
        d.dq.setConstant(nan);
        d.dqd.setConstant(nan);
        d.dtau.setConstant(nan);
        d.dphi.setConstant(nan);
      }
      put<nq, 1>(qdd + k * nq, d.qdd);
      put<nq, nq>(dq + k * nq * nq, d.dq);
      put<nq, nq>(dqd + k * nq * nq, d.dqd);
      put<nq, nq>(dtau + k * nq * nq, d.dtau);
      put<nq, np>(dphi + k * nq * np, d.dphi);
      min_pivot[k] = d.min_pivot;
    }
  }
  static void forward_kinematics(const double* q, double* pose, Batch b) {
    Eigen::Matrix<double, 4, 4> t;
    for (std::ptrdiff_t k = 0; k < b.n; ++k) {
      Model::forward_kinematics(vec<nq>(q + k * nq), t);
      put<4, 4>(pose + k * 16, t);
    }
  }
  static void jacobian(const double* q, double* out, Batch b) {
    Eigen::Matrix<double, 6, nq> j;
    for (std::ptrdiff_t k = 0; k < b.n; ++k) {
      Model::jacobian(vec<nq>(q + k * nq), j);
      put<6, nq>(out + k * 6 * nq, j);
    }
  }
  static void base_from_standard(const double* s, double* phi, Batch b) {
    Eigen::Matrix<double, np, 1> p;
    for (std::ptrdiff_t k = 0; k < b.n; ++k) {
      Model::base_from_standard(vec<ns>(s + k * ns), p);
      put<np, 1>(phi + k * np, p);
    }
  }
};

}  // namespace detail

template <class Full, class Model>
ModelKernels model_kernels();

// Model I of the tuple Models of the robot whose full model is Full (and, when Tail, every
// later one).
template <class Full, class Models, std::size_t I, bool Tail>
void add_model_kernels(std::vector<ModelKernels>& out) {
  if constexpr (I < std::tuple_size_v<Models>) {
    out.push_back(model_kernels<Full, std::tuple_element_t<I, Models>>());
    if constexpr (Tail) add_model_kernels<Full, Models, I + 1, true>(out);
  }
}

template <class Full, class Model>
ModelKernels model_kernels() {
  using K = detail::Kernels<Model>;
  ModelKernels k;
  k.identification = &identify::identification_model<Model>;
  k.diagnosis = &diagnose::diagnosis_model<Full, Model>;
  k.nq = Model::nq;
  k.np = Model::np;
  k.ns = Model::ns;
  k.regressor = &K::regressor;
  k.inverse_dynamics = &K::inverse_dynamics;
  k.inertia = &K::inertia;
  k.nonlinear_effects = &K::nonlinear_effects;
  k.forward_dynamics = &K::forward_dynamics;
  k.inverse_dynamics_derivatives = &K::inverse_dynamics_derivatives;
  k.forward_dynamics_derivatives = &K::forward_dynamics_derivatives;
  k.forward_kinematics = &K::forward_kinematics;
  k.jacobian = &K::jacobian;
  k.base_from_standard = &K::base_from_standard;
  return k;
}

}  // namespace symoro::python
