// CLIE over a generated Model (interface in clie.hpp): the simulated torque at the measured
// samples, and the Ceres refinement whose one cost function holds every residual.
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
#include "symoro/identify/closed_loop_model.hpp"
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
Bounds parameter_bounds(const Eigen::VectorXd& phi0, const std::vector<bool>& rotor_inertia, const ClieOptions& options);

// Ceres' bounded Levenberg-Marquardt on `cost` from result.phi (inside the bounds) to its
// end point; fills the solver fields of `result` (phi, success, termination, iterations,
// evaluation counts).
void solve_bounded(ceres::CostFunction& cost, const Bounds& bounds, const ClieOptions& options, ClieResult& result);

// All residuals tau_m - tau_s at the samples (sample-major, joint fastest) in one block of
// np parameters; its Jacobian, -(filtered d tau_s / d phi) at the sample rows, is one row of
// the simulation's dtau per sample. A diverging simulation fails the evaluation, which Ceres
// takes as a rejected step.
template <class Model>
class ClieCost final : public ceres::CostFunction {
 public:
  static constexpr int n = Model::nq;
  static constexpr int np = Model::np;

  ClieCost(const ClosedLoopSimulator<Model>& sim, const preprocess::Samples& measured, const SampleGrid& grid)
      : sim_(sim), measured_(measured), grid_(grid) {
    set_num_residuals(static_cast<int>(grid.rows.size()) * n);
    mutable_parameter_block_sizes()->push_back(np);
  }

  // The residuals alone (no sensitivities); false on divergence.
  bool residuals(const Eigen::VectorXd& phi, Eigen::VectorXd& r, Divergence* why) const {
    r.resize(num_residuals());
    return evaluate(phi.data(), r.data(), nullptr, why);
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    return evaluate(parameters[0], residuals, jacobians ? jacobians[0] : nullptr, nullptr);
  }

  // Distinct points whose simulation diverged.
  int rejected() const { return rejected_; }

 private:
  // The last points evaluated, for residual-only requests that repeat them: Ceres' bounded
  // line search evaluates the full step, then evaluates it again as the candidate, and the
  // final point was evaluated with its Jacobian.
  struct Evaluated {
    Eigen::Matrix<double, np, 1> phi;
    bool ok = false;
    Divergence why;
    Eigen::VectorXd residuals;
  };

  bool evaluate(const double* phi_data, double* residuals, double* jacobian, Divergence* why) const {
    const Eigen::Map<const Eigen::Matrix<double, np, 1>> phi(phi_data);
    const Eigen::Index count = num_residuals();
    if (!jacobian)
      for (const Evaluated& e : evaluated_)
        if (e.residuals.size() == count && e.phi == phi) {
          if (e.ok) Eigen::Map<Eigen::VectorXd>(residuals, count) = e.residuals;
          if (why) *why = e.why;
          return e.ok;
        }
    Evaluated& slot = evaluated_[next_slot_];
    next_slot_ = (next_slot_ + 1) % evaluated_.size();
    slot.phi = phi;
    slot.residuals.resize(count);
    slot.ok = simulate_residuals(phi, slot.residuals.data(), jacobian, &slot.why);
    if (!slot.ok) ++rejected_;
    if (slot.ok) Eigen::Map<Eigen::VectorXd>(residuals, count) = slot.residuals;
    if (why) *why = slot.why;
    return slot.ok;
  }

  bool simulate_residuals(const Eigen::Matrix<double, np, 1>& phi, double* residuals, double* jacobian,
                          Divergence* why) const {
    if (!sim_.simulate(phi, tau_, jacobian ? &dtau_ : nullptr, why)) return false;
    lowpass(grid_, tau_);
    const Eigen::Index samples = static_cast<Eigen::Index>(grid_.rows.size());
    for (Eigen::Index s = 0; s < samples; ++s)
      for (int j = 0; j < n; ++j) residuals[s * n + j] = measured_.tau(s, j) - tau_(grid_.rows[s], j);
    if (jacobian) {
      lowpass(grid_, dtau_);
      // A dtau row is d tau_j / d phi_i at j * np + i: the sample's n Jacobian rows, row-major.
      for (Eigen::Index s = 0; s < samples; ++s)
        Eigen::Map<Eigen::Matrix<double, 1, n * np>>(jacobian + s * n * np) = -dtau_.row(grid_.rows[s]);
    }
    return true;
  }

  const ClosedLoopSimulator<Model>& sim_;
  const preprocess::Samples& measured_;
  const SampleGrid& grid_;
  // Reused between evaluations (dtau is the large one: cycles x n np).
  mutable preprocess::Channels tau_, dtau_;
  mutable int rejected_ = 0;
  mutable std::array<Evaluated, 2> evaluated_;
  mutable std::size_t next_slot_ = 0;
};

template <class Model>
void check_clie_inputs(const preprocess::Samples& measured, const Eigen::VectorXd& phi) {
  if (phi.size() != Model::np)
    throw std::invalid_argument("CLIE: phi has " + std::to_string(phi.size()) + " entries, the model " +
                                std::to_string(Model::np));
  if (measured.tau.cols() != Model::nq || measured.tau.rows() != measured.time.size())
    throw std::invalid_argument("CLIE: the measured samples need time and an " + std::to_string(Model::nq) +
                                "-joint tau of as many rows");
}

}  // namespace detail

// The simulated torque at the samples' grid (filtered as the measurement when
// options.filter): rows match measured.time. Returns false on divergence (fills *why).
template <class Model>
bool simulated_samples(const ClosedLoopSimulator<Model>& sim, const preprocess::Samples& measured,
                       const Eigen::VectorXd& phi, const ClieOptions& options, Eigen::MatrixXd& tau, Divergence* why) {
  detail::check_clie_inputs<Model>(measured, phi);
  const detail::SampleGrid grid = detail::sample_grid(measured, sim.period(), sim.cycles(), options);
  preprocess::Channels simulated;
  if (!sim.simulate(phi, simulated, nullptr, why)) return false;
  detail::lowpass(grid, simulated);
  tau.resize(static_cast<Eigen::Index>(grid.rows.size()), Model::nq);
  for (Eigen::Index s = 0; s < tau.rows(); ++s) tau.row(s) = simulated.row(grid.rows[s]);
  return true;
}

template <class Model>
ClieResult clie(const ClosedLoopSimulator<Model>& sim, const preprocess::Samples& measured,
                const Eigen::VectorXd& phi0, const ClieOptions& options = {}) {
  const auto wall0 = std::chrono::steady_clock::now();
  const auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count(); };
  detail::check_clie_inputs<Model>(measured, phi0);
  const detail::SampleGrid grid = detail::sample_grid(measured, sim.period(), sim.cycles(), options);
  std::vector<bool> rotor_inertia(Model::np);
  for (int i = 0; i < Model::np; ++i) rotor_inertia[i] = std::string(Model::parameters[i].family) == "IA";
  const detail::Bounds bounds = detail::parameter_bounds(phi0, rotor_inertia, options);

  ClieResult result;
  result.phi = phi0.cwiseMax(bounds.lower).cwiseMin(bounds.upper);
  detail::ClieCost<Model> cost(sim, measured, grid);
  Eigen::VectorXd r;
  if (!cost.residuals(result.phi, r, &result.start_divergence)) {
    result.termination = "not started: the starting point's simulation diverges (" + result.start_divergence.describe() + ")";
    result.wall = elapsed();
    return result;
  }
  result.initial_cost = 0.5 * r.squaredNorm();
  result.rms_initial = detail::rms_per_joint(r, Model::nq);

  const Eigen::VectorXd start = result.phi;
  detail::solve_bounded(cost, bounds, options, result);
  result.rejected_divergent = cost.rejected();
  // Ceres ends on a point it evaluated successfully, so this cannot diverge; if it did, the
  // start is what remains valid.
  Divergence why;
  if (cost.residuals(result.phi, r, &why)) {
    result.final_cost = 0.5 * r.squaredNorm();
    result.rms_final = detail::rms_per_joint(r, Model::nq);
  } else {
    result.success = false;
    result.termination += "; the end point diverges (" + why.describe() + "), the start is kept";
    result.phi = start;
    result.final_cost = result.initial_cost;
    result.rms_final = result.rms_initial;
  }
  for (int i = 0; i < Model::np; ++i)
    if (result.phi(i) <= bounds.lower(i) || result.phi(i) >= bounds.upper(i)) result.at_bound.push_back(i);
  result.wall = elapsed();
  return result;
}

}  // namespace symoro::identify
