// A generated robot as the robot library's C ABI (symoro/robot_abi.h): the generated functions
// instantiated in double over fixed-size Eigen maps of the caller's arrays, and the model's
// constants copied into the C structs. Included only by a robot library's units, which symoroc
// build writes (codegen/src/robot_library.cpp): two units per model (this one, and the second
// derivatives' in robot_abi_second_derivatives-inl.hpp), then one that gathers them.
#pragma once

#include <array>
#include <cstddef>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "symoro/model_info.hpp"
#include "symoro/robot_abi.h"
#include "symoro/robot_abi_export.hpp"

namespace symoro::abi_export {

template <class T, class = void>
struct Effects {
  static constexpr int count = 0;
  static const symoro_abi_effect_parameter* table() { return nullptr; }
};
template <class Model>
struct Effects<Model, std::void_t<decltype(Model::ne)>> {
  static constexpr int count = Model::ne;
  static const symoro_abi_effect_parameter* table() {
    static const auto t = [] {
      std::array<symoro_abi_effect_parameter, Model::ne> a{};
      for (std::size_t i = 0; i < a.size(); ++i) {
        const EffectParameterInfo& e = Model::effect_parameters[i];
        a[i] = {e.name, e.family, e.joint, e.order, e.velocity};
      }
      return a;
    }();
    return t.data();
  }
};

template <class Model>
struct Kernels {
  static constexpr int n = Model::nq, np = Model::np, ns = Model::ns, parent_np = Model::Parent::np;
  // The state (q, qd, qdd, tau) as local copies: read through maps of the caller's arrays, every
  // store into an output might alias them, so the compiler reloaded them and kept dead stores
  // (the regressor 25-60 ns slower than inline, bench_robot_library). Parameter vectors stay maps:
  // copying them cost more (10-14 ns for inverse_dynamics) than it saved.
  template <int R>
  static Eigen::Matrix<double, R, 1> in(const double* p) {
    return Eigen::Map<const Eigen::Matrix<double, R, 1>>(p);
  }
  template <int R>
  static Eigen::Map<const Eigen::Matrix<double, R, 1>> map(const double* p) {
    return Eigen::Map<const Eigen::Matrix<double, R, 1>>(p);
  }
  template <int R, int C = 1>
  using Out = Eigen::Map<Eigen::Matrix<double, R, C>>;
  using Mat = Eigen::Matrix<double, n, n>;

  static void regressor(const double* q, const double* qd, const double* qdd, double* w) {
    Out<n, np> W(w);
    Model::regressor(in<n>(q), in<n>(qd), in<n>(qdd), W);
  }
  static void fixed_torque(const double* q, const double* qd, const double* qdd, double* tau) {
    Out<n> t(tau);
    Model::fixed_torque(in<n>(q), in<n>(qd), in<n>(qdd), t);
  }
  static void inverse_dynamics(const double* q, const double* qd, const double* qdd, const double* phi, double* tau) {
    Out<n> t(tau);
    Model::inverse_dynamics(in<n>(q), in<n>(qd), in<n>(qdd), map<np>(phi), t);
  }
  static void inertia(const double* q, const double* phi, double* m) {
    Out<n, n> M(m);
    Model::inertia(in<n>(q), map<np>(phi), M);
  }
  static void inertia_basis(const double* q, double* constant, double* linear) {
    // np fixed n x n matrices: off the caller's (maybe a worker thread's) stack.
    thread_local typename Model::template InertiaBasis<double> b;
    Model::inertia_basis(in<n>(q), b);
    Out<n, n>{constant} = b.constant;
    for (int i = 0; i < np; ++i) Out<n, n>{linear + static_cast<std::ptrdiff_t>(i)* n* n} = b.linear[i];
  }
  static void nonlinear_effects(const double* q, const double* qd, const double* phi, double* h) {
    Out<n> t(h);
    Model::nonlinear_effects(in<n>(q), in<n>(qd), map<np>(phi), t);
  }
  static void forward_dynamics(const double* q, const double* qd, const double* tau, const double* phi, double* qdd) {
    Out<n> a(qdd);
    Model::forward_dynamics(in<n>(q), in<n>(qd), in<n>(tau), map<np>(phi), a);
  }
  static void inverse_dynamics_derivatives(const double* q, const double* qd, const double* qdd, const double* phi,
                                           double* tau, double* dq, double* dqd) {
    typename Model::template InverseDynamicsDerivatives<double> d;
    Model::inverse_dynamics_derivatives(in<n>(q), in<n>(qd), in<n>(qdd), map<np>(phi), d);
    Out<n>{tau} = d.tau;
    Out<n, n>{dq} = d.dq;
    Out<n, n>{dqd} = d.dqd;
  }
  static int forward_dynamics_derivatives(const double* q, const double* qd, const double* tau, const double* phi,
                                          double* qdd, double* dq, double* dqd, double* dtau, double* dphi,
                                          double* min_pivot) {
    thread_local typename Model::template ForwardDynamicsDerivatives<double> d;
    const bool ok = Model::forward_dynamics_derivatives(in<n>(q), in<n>(qd), in<n>(tau), map<np>(phi), d);
    Out<n>{qdd} = d.qdd;
    Out<n, n>{dq} = d.dq;
    Out<n, n>{dqd} = d.dqd;
    Out<n, n>{dtau} = d.dtau;
    Out<n, np>{dphi} = d.dphi;
    *min_pivot = d.min_pivot;
    return ok ? 1 : 0;
  }
  static void inertia_derivatives(const double* q, const double* phi, double* m, double* dm) {
    thread_local typename Model::template InertiaDerivatives<double> d;
    Model::inertia_derivatives(in<n>(q), map<np>(phi), d);
    Out<n, n>{m} = d.M;
    for (int k = 0; k < n; ++k) Out<n, n>{dm + static_cast<std::ptrdiff_t>(k)* n* n} = d.dq[k];
  }
  static void forward_kinematics(const double* q, double* t) {
    Out<4, 4> T(t);
    Model::forward_kinematics(in<n>(q), T);
  }
  static void jacobian(const double* q, double* j) {
    Out<6, n> J(j);
    Model::jacobian(in<n>(q), J);
  }
  static void base_from_standard(const double* s, double* phi) {
    Out<np> p(phi);
    Model::base_from_standard(map<ns>(s), p);
  }
  static void to_parent(const double* phi, double* parent) { Out<parent_np>{parent} = Model::to_parent(map<np>(phi)); }
  static void from_parent(const double* parent, double* phi) {
    Out<np>{phi} = Model::from_parent(map<parent_np>(parent));
  }
};

template <class Model>
symoro_abi_model model_abi() {
  using K = Kernels<Model>;
  static const auto parameters = [] {
    std::array<symoro_abi_parameter, Model::np> a{};
    for (std::size_t i = 0; i < a.size(); ++i) {
      const ParameterInfo& p = Model::parameters[i];
      a[i] = {p.name, p.family, p.joint, p.unit};
    }
    return a;
  }();
  static const auto standard = [] {
    std::array<symoro_abi_standard_parameter, Model::ns> a{};
    for (std::size_t i = 0; i < a.size(); ++i) {
      const StandardParameterInfo& p = Model::standard_parameters[i];
      a[i] = {p.name, p.family, p.joint};
    }
    return a;
  }();
  static const auto fixed = [] {
    std::vector<symoro_abi_fixed_parameter> a;
    for (const FixedParameter& f : Model::fixed_parameters) a.push_back({f.name, f.value});
    return a;
  }();
  static const auto parent_index = [] {
    std::array<int, Model::np> a{};
    for (std::size_t i = 0; i < a.size(); ++i) a[i] = Model::parent_index[i];
    return a;
  }();
  static const auto joints = [] {
    std::array<symoro_abi_joint, Model::nq> a{};
    for (std::size_t i = 0; i < a.size(); ++i) {
      const JointInfo& j = Model::joints[i];
      a[i] = {j.name, static_cast<int>(j.type), j.lower, j.upper, j.velocity, j.effort, j.audit_lower, j.audit_upper};
    }
    return a;
  }();
  static const auto frames = [] {
    std::array<symoro_abi_frame, Model::nf> a{};
    for (std::size_t i = 0; i < a.size(); ++i) {
      const FrameInfo& f = Model::frames[i];
      a[i] = {f.ant, f.sigma, f.mu, f.gamma, f.b, f.alpha, f.d, f.theta, f.r};
    }
    return a;
  }();
  symoro_abi_model m{};
  m.variant = Model::variant_name;
  m.description = Model::description;
  m.nq = Model::nq;
  m.np = Model::np;
  m.ns = Model::ns;
  m.nf = Model::nf;
  m.ne = Effects<Model>::count;
  m.n_fixed = static_cast<int>(fixed.size());
  m.parent_np = Model::Parent::np;
  m.parameters = parameters.data();
  m.standard = standard.data();
  m.effects = Effects<Model>::table();
  m.fixed = fixed.data();
  m.parent_index = parent_index.data();
  m.joints = joints.data();
  m.frames = frames.data();
  for (int i = 0; i < 3; ++i) m.gravity[i] = Model::gravity[static_cast<std::size_t>(i)];
  m.regressor = &K::regressor;
  m.fixed_torque = &K::fixed_torque;
  m.inverse_dynamics = &K::inverse_dynamics;
  m.inertia = &K::inertia;
  m.inertia_basis = &K::inertia_basis;
  m.nonlinear_effects = &K::nonlinear_effects;
  m.forward_dynamics = &K::forward_dynamics;
  m.inverse_dynamics_derivatives = &K::inverse_dynamics_derivatives;
  m.forward_dynamics_derivatives = &K::forward_dynamics_derivatives;
  m.inertia_derivatives = &K::inertia_derivatives;
  m.inertia_second_derivatives = &inertia_second_derivatives<Model>;
  m.forward_kinematics = &K::forward_kinematics;
  m.jacobian = &K::jacobian;
  m.base_from_standard = &K::base_from_standard;
  m.to_parent = &K::to_parent;
  m.from_parent = &K::from_parent;
  return m;
}

}  // namespace symoro::abi_export
