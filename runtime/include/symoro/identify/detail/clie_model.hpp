// CLIE's internals (clie.cpp) and its entry points for a generated Model's closed loop
// (ClosedLoopSimulator<Model>), which forward to the model-independent ones of clie.hpp.
#pragma once

#include <array>
#include <chrono>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <ceres/cost_function.h>

#include "symoro/identify/clie.hpp"
#include "symoro/identify/detail/closed_loop_model.hpp"
#include "symoro/preprocess/butterworth.hpp"
#include "symoro/preprocess/channels.hpp"

namespace symoro::identify {

namespace detail {

// Where the measured samples lie in the simulation and the low-pass they went through.
struct SampleGrid {
  std::vector<Eigen::Index> rows;  // simulated cycle of each sample
  bool filter = false;
  std::vector<preprocess::Biquad> sections;
  int padding = 0;
};

// clie.cpp. Throws std::invalid_argument when the samples do not fit the simulation (a time off
// the cycle grid or beyond it, a filter the run is too short for, another base period).
SampleGrid sample_grid(const preprocess::Samples& measured, double period, int cycles, const ClieOptions& options);
// The measurement's zero-phase low-pass over every channel (nothing when the grid has none).
void lowpass(const SampleGrid& grid, preprocess::Channels& signals);
// Per-joint rms of residuals stored sample by sample (joint fastest).
Eigen::VectorXd rms_per_joint(const Eigen::VectorXd& residuals, int joints);

struct Bounds {
  Eigen::VectorXd lower, upper;
};
// phi0_i -+ max(bound_factor |phi0_i|, min_bound); rotor inertias at least min_rotor_inertia.
Bounds parameter_bounds(const Eigen::VectorXd& phi0, const std::vector<bool>& rotor_inertia,
                        const ClieOptions& options);

// Ceres' bounded Levenberg-Marquardt on `cost` from result.phi (inside the bounds) to its
// end point; fills the solver fields of `result` (phi, success, termination, iterations,
// evaluation counts).
void solve_bounded(ceres::CostFunction& cost, const Bounds& bounds, const ClieOptions& options, ClieResult& result);

}  // namespace detail

// The model-independent CLIE of clie.hpp on a generated Model's closed loop (kept so that code
// written against the templates compiles unchanged).
template <class Model>
bool simulated_samples(const ClosedLoopSimulator<Model>& sim, const preprocess::Samples& measured,
                       const Eigen::VectorXd& phi, const ClieOptions& options, Eigen::MatrixXd& tau, Divergence* why) {
  return simulated_samples(static_cast<const ClosedLoop&>(sim), measured, phi, options, tau, why);
}

template <class Model>
ClieResult clie(const ClosedLoopSimulator<Model>& sim, const preprocess::Samples& measured, const Eigen::VectorXd& phi0,
                const ClieOptions& options = {}) {
  return clie(static_cast<const ClosedLoop&>(sim), measured, phi0, options);
}

}  // namespace symoro::identify
