// A compiled model as the Python package calls it: plain functions over a batch of states in
// C-ordered float64 arrays (NumPy's layout), so that the binding code is compiled once and only
// these loops are compiled per model (model_kernels-inl.hpp, one unit per robot model). Each
// computes what the generated function gives in C++, into the model's own fixed-size Eigen
// types, then copies it out: the results are those of the C++ call, bit for bit.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "symoro/diagnose/diagnosis_model.hpp"
#include "symoro/identify/identification_model.hpp"

namespace symoro::python {

// n states; an input with stride 0 is one row for every state (e.g. one phi for a batch).
struct Batch {
  std::ptrdiff_t n = 1;
  std::ptrdiff_t phi_stride = 0;  // np, or 0
};

struct ModelKernels {
  // The model's description, its identification interface (studies), its diagnosis interface
  // (diagnose) and its sizes.
  std::shared_ptr<const identify::IdentificationModel> (*identification)() = nullptr;
  std::shared_ptr<const diagnose::DiagnosisModel> (*diagnosis)() = nullptr;
  int nq = 0, np = 0, ns = 0;

  // (n, nq, np)
  void (*regressor)(const double* q, const double* qd, const double* qdd, double* w, Batch b) = nullptr;
  // (n, nq)
  void (*inverse_dynamics)(const double* q, const double* qd, const double* qdd, const double* phi, double* tau,
                           Batch b) = nullptr;
  // (n, nq, nq)
  void (*inertia)(const double* q, const double* phi, double* m, Batch b) = nullptr;
  // (n, nq)
  void (*nonlinear_effects)(const double* q, const double* qd, const double* phi, double* h, Batch b) = nullptr;
  // (n, nq)
  void (*forward_dynamics)(const double* q, const double* qd, const double* tau, const double* phi, double* qdd,
                           Batch b) = nullptr;
  // tau (n, nq), d tau / d q and d qd (n, nq, nq)
  void (*inverse_dynamics_derivatives)(const double* q, const double* qd, const double* qdd, const double* phi,
                                       double* tau, double* dq, double* dqd, Batch b) = nullptr;
  // qdd (n, nq), d qdd / d q, d qd, d tau (n, nq, nq), d phi (n, nq, np), min_pivot (n): where M
  // is not positive definite (min_pivot <= 0) the derivatives are NaN.
  void (*forward_dynamics_derivatives)(const double* q, const double* qd, const double* tau, const double* phi,
                                       double* qdd, double* dq, double* dqd, double* dtau, double* dphi,
                                       double* min_pivot, Batch b) = nullptr;
  // (n, 4, 4): the last arm frame in frame 0
  void (*forward_kinematics)(const double* q, double* pose, Batch b) = nullptr;
  // (n, 6, nq)
  void (*jacobian)(const double* q, double* j, Batch b) = nullptr;
  // (n, np) from (n, ns)
  void (*base_from_standard)(const double* s, double* phi, Batch b) = nullptr;
};

template <class Full, class Model>
ModelKernels model_kernels();

// Every compiled robot model (generated: <build>/robot_units/python_robots.cpp).
std::vector<ModelKernels> all_model_kernels();

}  // namespace symoro::python
