// A robot model as the Python package calls it: functions over a batch of states in C-ordered
// float64 arrays (NumPy's layout), written once over a model handle (loaded_kernels.cpp): a robot
// library loaded at run time (symoro.load) or a model linked into the module (python_robots.cpp).
// Each calls the generated function's C ABI kernel and copies its column-major result out: the
// results are those of the C++ call, bit for bit.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <vector>

#include "symoro/diagnose/diagnosis_model.hpp"
#include "symoro/identify/identification_model.hpp"
#include "symoro/robot/model_handle.hpp"

namespace symoro::python {

// n states; an input with stride 0 is one row for every state (e.g. one phi for a batch).
struct Batch {
  std::ptrdiff_t n = 1;
  std::ptrdiff_t phi_stride = 0;  // np, or 0
};

struct ModelKernels {
  // The model's description, its identification interface (studies), its diagnosis interface
  // (diagnose) and its sizes.
  std::function<std::shared_ptr<const identify::IdentificationModel>()> identification;
  std::function<std::shared_ptr<const diagnose::DiagnosisModel>()> diagnosis;
  int nq = 0, np = 0, ns = 0;
  std::shared_ptr<const robot::ModelHandle> handle;  // the handle itself (the momentum observer)

  // (n, nq, np)
  std::function<void(const double* q, const double* qd, const double* qdd, double* w, Batch b)> regressor;
  // (n, nq)
  std::function<void(const double* q, const double* qd, const double* qdd, const double* phi, double* tau, Batch b)>
      inverse_dynamics;
  // (n, nq, nq)
  std::function<void(const double* q, const double* phi, double* m, Batch b)> inertia;
  // (n, nq)
  std::function<void(const double* q, const double* qd, const double* phi, double* h, Batch b)> nonlinear_effects;
  // (n, nq)
  std::function<void(const double* q, const double* qd, const double* tau, const double* phi, double* qdd, Batch b)>
      forward_dynamics;
  // tau (n, nq), d tau / d q and d qd (n, nq, nq)
  std::function<void(const double* q, const double* qd, const double* qdd, const double* phi, double* tau, double* dq,
                     double* dqd, Batch b)>
      inverse_dynamics_derivatives;
  // qdd (n, nq), d qdd / d q, d qd, d tau (n, nq, nq), d phi (n, nq, np), min_pivot (n): where M
  // is not positive definite (min_pivot <= 0) the derivatives are NaN.
  std::function<void(const double* q, const double* qd, const double* tau, const double* phi, double* qdd, double* dq,
                     double* dqd, double* dtau, double* dphi, double* min_pivot, Batch b)>
      forward_dynamics_derivatives;
  // (n, 4, 4): the last arm frame in frame 0
  std::function<void(const double* q, double* pose, Batch b)> forward_kinematics;
  // (n, 6, nq)
  std::function<void(const double* q, double* j, Batch b)> jacobian;
  // (n, np) from (n, ns)
  std::function<void(const double* s, double* phi, Batch b)> base_from_standard;
};

// Every compiled robot model (generated: <build>/robot_units/python_robots.cpp).
std::vector<ModelKernels> all_model_kernels();

// The batch loops over a model's functions, without its identification and diagnosis interfaces.
ModelKernels handle_kernels(const robot::ModelHandle& model);

// A model of a robot library loaded at run time (symoro.load) or linked in (loaded_kernels.cpp):
// the loops and its interfaces. full: its robot's full model.
ModelKernels loaded_kernels(const robot::ModelHandle& model, const robot::ModelHandle& full);

}  // namespace symoro::python
