// ModelKernels over a model handle (a loaded robot library's, symoro.load, or a model linked into
// the module, python_robots.cpp): the batch loops written once over its functions
// (symoro/robot_abi.h: column-major outputs), each result turned into NumPy's C order.
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "model_kernels.hpp"
#include "symoro/diagnose/loaded_model.hpp"
#include "symoro/identify/loaded_model.hpp"

namespace symoro::python {

namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Scratch for one state's column-major result, reused by the thread: no allocation per call.
double* scratch(std::size_t size) {
  thread_local std::vector<double> buffer;
  if (buffer.size() < size) buffer.resize(size);
  return buffer.data();
}

// A column-major r x c result into C order at out.
void put(double* out, const double* column_major, int r, int c) {
  Eigen::Map<RowMajor>(out, r, c) = Eigen::Map<const Eigen::MatrixXd>(column_major, r, c);
}

}  // namespace

ModelKernels loaded_kernels(const robot::ModelHandle& model, const robot::ModelHandle& full) {
  ModelKernels k = handle_kernels(model);
  const auto id = identify::identification_model(model, full);
  const auto diagnosis = diagnose::diagnosis_model(model, full);
  k.identification = [id] { return id; };
  k.diagnosis = [diagnosis] { return diagnosis; };
  return k;
}

ModelKernels handle_kernels(const robot::ModelHandle& model) {
  const robot::ModelHandle m = model;
  const int nq = m.nq(), np = m.np(), ns = m.ns();
  ModelKernels k;
  k.handle = std::make_shared<const robot::ModelHandle>(m);
  k.nq = nq;
  k.np = np;
  k.ns = ns;
  k.regressor = [m, nq, np](const double* q, const double* qd, const double* qdd, double* w, Batch b) {
    double* t = scratch(static_cast<std::size_t>(nq) * np);
    for (std::ptrdiff_t i = 0; i < b.n; ++i) {
      m.regressor(q + i * nq, qd + i * nq, qdd + i * nq, t);
      put(w + i * nq * np, t, nq, np);
    }
  };
  k.inverse_dynamics = [m, nq](const double* q, const double* qd, const double* qdd, const double* phi, double* tau,
                               Batch b) {
    for (std::ptrdiff_t i = 0; i < b.n; ++i)
      m.inverse_dynamics(q + i * nq, qd + i * nq, qdd + i * nq, phi + i * b.phi_stride, tau + i * nq);
  };
  k.inertia = [m, nq](const double* q, const double* phi, double* out, Batch b) {
    double* t = scratch(static_cast<std::size_t>(nq) * nq);
    for (std::ptrdiff_t i = 0; i < b.n; ++i) {
      m.inertia(q + i * nq, phi + i * b.phi_stride, t);
      put(out + i * nq * nq, t, nq, nq);
    }
  };
  k.nonlinear_effects = [m, nq](const double* q, const double* qd, const double* phi, double* h, Batch b) {
    for (std::ptrdiff_t i = 0; i < b.n; ++i)
      m.nonlinear_effects(q + i * nq, qd + i * nq, phi + i * b.phi_stride, h + i * nq);
  };
  k.forward_dynamics = [m, nq](const double* q, const double* qd, const double* tau, const double* phi, double* qdd,
                               Batch b) {
    for (std::ptrdiff_t i = 0; i < b.n; ++i)
      m.forward_dynamics(q + i * nq, qd + i * nq, tau + i * nq, phi + i * b.phi_stride, qdd + i * nq);
  };
  k.inverse_dynamics_derivatives = [m, nq](const double* q, const double* qd, const double* qdd, const double* phi,
                                           double* tau, double* dq, double* dqd, Batch b) {
    std::vector<double> a(static_cast<std::size_t>(nq) * nq), c(a.size());
    for (std::ptrdiff_t i = 0; i < b.n; ++i) {
      m.inverse_dynamics_derivatives(q + i * nq, qd + i * nq, qdd + i * nq, phi + i * b.phi_stride, tau + i * nq,
                                     a.data(), c.data());
      put(dq + i * nq * nq, a.data(), nq, nq);
      put(dqd + i * nq * nq, c.data(), nq, nq);
    }
  };
  k.forward_dynamics_derivatives = [m, nq, np](const double* q, const double* qd, const double* tau, const double* phi,
                                               double* qdd, double* dq, double* dqd, double* dtau, double* dphi,
                                               double* min_pivot, Batch b) {
    const std::size_t nn = static_cast<std::size_t>(nq) * nq;
    std::vector<double> a(nq), x(nn), y(nn), z(nn), w(static_cast<std::size_t>(nq) * np);
    for (std::ptrdiff_t i = 0; i < b.n; ++i) {
      if (!m.forward_dynamics_derivatives(q + i * nq, qd + i * nq, tau + i * nq, phi + i * b.phi_stride, a.data(),
                                          x.data(), y.data(), z.data(), w.data(), min_pivot + i)) {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        for (auto* v : {&a, &x, &y, &z, &w}) std::fill(v->begin(), v->end(), nan);
      }
      std::copy(a.begin(), a.end(), qdd + i * nq);
      put(dq + i * nq * nq, x.data(), nq, nq);
      put(dqd + i * nq * nq, y.data(), nq, nq);
      put(dtau + i * nq * nq, z.data(), nq, nq);
      put(dphi + i * nq * np, w.data(), nq, np);
    }
  };
  k.forward_kinematics = [m, nq](const double* q, double* pose, Batch b) {
    double t[16];
    for (std::ptrdiff_t i = 0; i < b.n; ++i) {
      m.forward_kinematics(q + i * nq, t);
      put(pose + i * 16, t, 4, 4);
    }
  };
  k.jacobian = [m, nq](const double* q, double* out, Batch b) {
    double* t = scratch(static_cast<std::size_t>(6) * nq);
    for (std::ptrdiff_t i = 0; i < b.n; ++i) {
      m.jacobian(q + i * nq, t);
      put(out + i * 6 * nq, t, 6, nq);
    }
  };
  k.base_from_standard = [m, np, ns](const double* s, double* phi, Batch b) {
    for (std::ptrdiff_t i = 0; i < b.n; ++i) m.base_from_standard(s + i * ns, phi + i * np);
  };
  return k;
}

}  // namespace symoro::python
