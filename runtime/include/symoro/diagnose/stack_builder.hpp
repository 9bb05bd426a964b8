// Builds a DesignStack from logs preprocessed at their own rate, by parallel filtering
// (Gautier): every regressor column (identified model, full model, candidate effects) and the
// torque are computed sample by sample from lightly filtered q, qd, qdd, then all pass through
// the same zero-phase low-pass and are decimated to the diagnosis grid. Since the low-pass is
// linear, y = W phi holds after it exactly as before it; filtering q first and evaluating the
// nonlinear model on it afterwards does not (gravity and inertia are nonlinear in q), which
// leaves a residual on the loaded joints that looks like a missing effect.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/diagnose/design_stack.hpp"
#include "symoro/diagnose/effects.hpp"
#include "symoro/model_info.hpp"
#include "symoro/preprocess/preprocess.hpp"

namespace symoro::diagnose {

struct NamedSamples {
  std::string name;
  preprocess::Samples samples;  // at the log's base period, lightly filtered (light_preprocessing)
};

struct StackOptions {
  double interval = 0.01;  // s, the diagnosis grid
  double cutoff = 5.0;     // Hz, the low-pass on every column and the torque
  int order = 4;
  // Samples this many of the low-pass's slowest time constants from either end of a piece are
  // left out: the zero-phase filter's end extension is not the signal (a torque spike in a
  // log's first row spreads over ~5 time constants).
  double edge_time_constants = 6;
  // The candidate effects' own terms (friction: sign-like in qd) take qd low-passed to this
  // cutoff: noise in qd smooths a sign by its own spread, and the wide band the regressor
  // needs (light_preprocessing) carries ~0.1 rad/s of quantization noise, more than the
  // friction's velocity scales. 0: the samples' qd as given.
  double effect_velocity_cutoff = 20.0;  // Hz
  CandidateOptions candidates;
};

// The light preprocessing the builder expects: the base period, a cutoff only to tame the
// derivatives of quantized positions, and above the drives' vibration modes (gear mesh,
// ~100 Hz). The regressor is nonlinear in qd: vibration removed before it (a 20 Hz cutoff
// did) is missing from its Coriolis and centrifugal terms, while the torque keeps their
// rectified part, which then passes the diagnosis low-pass as a slow misfit on the loaded
// joints (a spurious offset on joint 2 with a 4 ms delay or with backlash on the twin).
// The derivative noise it lets in is averaged by the low-pass where it enters linearly; its
// square biases the velocity-squared terms by well under a mN m at 4096 counts/rev.
inline preprocess::Options light_preprocessing(double cutoff_hz = 150.0) {
  preprocess::Options options;
  options.derivative_cutoff = cutoff_hz;
  return options;
}

// What the design stack needs of the diagnosed model and of its robot's full model: their
// descriptions and the generated regressors (column-major, caller-owned outputs), from a
// generated Model (stack_model<Full, Identified>) or a loaded robot library's models.
struct StackModel {
  int nq = 0, np = 0, ns = 0;
  std::vector<JointInfo> joints;
  std::vector<ParameterInfo> parameters, full_parameters;
  std::vector<StandardParameterInfo> standard;
  std::function<void(const double* q, const double* qd, const double* qdd, double* W)> regressor;  // nq x np
  std::function<void(const double* q, const double* qd, const double* qdd, double* tau)> fixed_torque;
  std::function<void(const double* q, const double* qd, const double* qdd, double* W)> full_regressor;  // nq x full np
  std::function<void(const double* s, double* phi)> base_from_standard;
};

// The design stack of `runs` (stack_builder.cpp, compiled once for every robot).
DesignStack stack_design(const StackModel& model, const std::vector<NamedSamples>& runs,
                         const StackOptions& options = {});

// A generated model and its full model as a StackModel.
template <class Full, class Identified>
StackModel stack_model() {
  static_assert(Full::nq == Identified::nq, "the full and identified models must have the same joints");
  constexpr int n = Identified::nq;
  using In = Eigen::Map<const Eigen::Matrix<double, n, 1>>;
  StackModel m;
  m.nq = n;
  m.np = Identified::np;
  m.ns = Identified::ns;
  m.joints.assign(Identified::joints.begin(), Identified::joints.end());
  m.parameters.assign(Identified::parameters.begin(), Identified::parameters.end());
  m.full_parameters.assign(Full::parameters.begin(), Full::parameters.end());
  m.standard.assign(Identified::standard_parameters.begin(), Identified::standard_parameters.end());
  m.regressor = [](const double* q, const double* qd, const double* qdd, double* w) {
    Eigen::Map<Eigen::Matrix<double, n, Identified::np>> W(w);
    Identified::regressor(In(q), In(qd), In(qdd), W);
  };
  m.fixed_torque = [](const double* q, const double* qd, const double* qdd, double* tau) {
    Eigen::Map<Eigen::Matrix<double, n, 1>> t(tau);
    Identified::fixed_torque(In(q), In(qd), In(qdd), t);
  };
  m.full_regressor = [](const double* q, const double* qd, const double* qdd, double* w) {
    Eigen::Map<Eigen::Matrix<double, n, Full::np>> W(w);
    Full::regressor(In(q), In(qd), In(qdd), W);
  };
  m.base_from_standard = [](const double* s, double* phi) {
    Eigen::Map<Eigen::Matrix<double, Identified::np, 1>> p(phi);
    Identified::base_from_standard(Eigen::Map<const Eigen::Matrix<double, Identified::ns, 1>>(s), p);
  };
  return m;
}

template <class Full, class Identified>
DesignStack stack_design(const std::vector<NamedSamples>& runs, const StackOptions& options = {}) {
  return stack_design(stack_model<Full, Identified>(), runs, options);
}

}  // namespace symoro::diagnose
