// The non-template parts of CLIE (clie_model.hpp): the sample grid and filter, the bounds and
// the Ceres solve.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <ceres/problem.h>
#include <ceres/solver.h>
#include <fmt/format.h>

#include "symoro/identify/clie_model.hpp"
#include "symoro/preprocess/zero_phase.hpp"

namespace symoro::identify::detail {

SampleGrid sample_grid(const preprocess::Samples& measured, double period, int cycles, const ClieOptions& options) {
  SampleGrid grid;
  const Eigen::Index samples = measured.time.size();
  if (samples == 0) throw std::invalid_argument("CLIE: no measured samples");
  grid.rows.resize(static_cast<std::size_t>(samples));
  for (Eigen::Index s = 0; s < samples; ++s) {
    // The log's first stamp is cycle 0: sample times are whole cycles from it.
    const double cycle = measured.time(s) / period;
    const long long k = std::llround(cycle);
    if (!(std::abs(cycle - static_cast<double>(k)) < 1e-6) || k < 0 || k >= cycles)
      throw std::invalid_argument(fmt::format(
          "CLIE: sample {} at t = {} s is not one of the simulation's cycles 0..{} of {} s", s, measured.time(s),
          cycles - 1, period));
    grid.rows[static_cast<std::size_t>(s)] = static_cast<Eigen::Index>(k);
  }
  grid.filter = options.filter;
  if (!grid.filter) return grid;

  // Exactly the low-pass preprocess() applied to the measured tau (preprocess.cpp).
  const preprocess::Options& o = options.preprocess;
  // The period the samples were preprocessed on (the log's own unless the options force one).
  // Samples made without preprocess() (no report, no forced period) are taken at the control
  // period.
  const double base = measured.report.base_period > 0 ? measured.report.base_period
                      : o.base_period > 0             ? o.base_period
                                                      : period;
  if (!(std::abs(period - base) <= 1e-9 * period))
    throw std::invalid_argument(fmt::format("CLIE: the control period {} s differs from the preprocessing base period {} s",
                                            period, base));
  const double cutoff = std::min(o.derivative_cutoff, o.anti_alias_fraction * 0.5 / measured.interval);
  if (measured.report.cutoff > 0 && !(std::abs(measured.report.cutoff - cutoff) <= 1e-9 * cutoff))
    throw std::invalid_argument(fmt::format(
        "CLIE: the measured samples were filtered at {} Hz, the options give {} Hz (pass the preprocessing options)",
        measured.report.cutoff, cutoff));
  grid.sections = preprocess::butterworth_lowpass(o.filter_order, cutoff, 1 / period);
  grid.padding = preprocess::zero_phase_padding(grid.sections);
  if (grid.padding >= cycles)
    throw std::invalid_argument(fmt::format("CLIE: {} simulated cycles are too few for the {:.3g} Hz filter's padding of {}",
                                            cycles, cutoff, grid.padding));
  return grid;
}

void lowpass(const SampleGrid& grid, preprocess::Channels& signals) {
  if (grid.filter) preprocess::filtfilt(grid.sections, grid.padding, signals);
}

Eigen::VectorXd rms_per_joint(const Eigen::VectorXd& residuals, int joints) {
  const Eigen::Index samples = residuals.size() / joints;
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> r(residuals.data(),
                                                                                                    samples, joints);
  return (r.colwise().squaredNorm().transpose() / static_cast<double>(std::max<Eigen::Index>(samples, 1))).cwiseSqrt();
}

Bounds parameter_bounds(const Eigen::VectorXd& phi0, const std::vector<bool>& rotor_inertia, const ClieOptions& options) {
  if (!(options.bound_factor >= 0) || !(options.min_bound > 0) || !(options.min_rotor_inertia >= 0))
    throw std::invalid_argument("CLIE: bound_factor >= 0, min_bound > 0 and min_rotor_inertia >= 0 needed");
  if (!phi0.allFinite()) throw std::invalid_argument("CLIE: the starting phi is not finite");
  if (!(options.std_bound >= 0)) throw std::invalid_argument("CLIE: std_bound must be >= 0");
  const bool by_std = options.std_bound > 0;
  if (by_std && (options.scale.size() != phi0.size() || !(options.scale.array() > 0).all() || !options.scale.allFinite()))
    throw std::invalid_argument(fmt::format("CLIE: std_bound needs {} positive standard deviations, got {}", phi0.size(),
                                            options.scale.size()));
  Bounds b;
  b.lower.resize(phi0.size());
  b.upper.resize(phi0.size());
  for (Eigen::Index i = 0; i < phi0.size(); ++i) {
    double half = std::max(options.bound_factor * std::abs(phi0(i)), options.min_bound);
    if (by_std) half = std::min(half, options.std_bound * options.scale(i));
    b.lower(i) = phi0(i) - half;
    b.upper(i) = phi0(i) + half;
    if (rotor_inertia[static_cast<std::size_t>(i)]) {
      // Rotor inertias are searched on the positive side only (paper Sec. IV-C).
      b.lower(i) = std::max(b.lower(i), options.min_rotor_inertia);
      b.upper(i) = std::max(b.upper(i), b.lower(i) + (by_std ? half : options.min_bound));
    }
  }
  return b;
}

void solve_bounded(ceres::CostFunction& cost, const Bounds& bounds, const ClieOptions& options, ClieResult& result) {
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  double* phi = result.phi.data();
  problem.AddResidualBlock(&cost, nullptr, phi);
  for (int i = 0; i < static_cast<int>(result.phi.size()); ++i) {
    problem.SetParameterLowerBound(phi, i, bounds.lower(i));
    problem.SetParameterUpperBound(phi, i, bounds.upper(i));
  }
  ceres::Solver::Options so;
  so.minimizer_type = ceres::TRUST_REGION;
  so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  // The step's linear solve is negligible next to the simulations (AG02 at 40 ms: 0.1 s of
  // 16 s with QR, 0.03 s with the normal equations, same result), so the better-conditioned QR.
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = options.max_iterations;
  so.function_tolerance = options.function_tolerance;
  so.parameter_tolerance = options.parameter_tolerance;
  so.gradient_tolerance = options.gradient_tolerance;
  // With bounds Ceres refines each step by a projected Armijo line search; its default cubic
  // interpolation asks for the gradient at every trial point, i.e. a full sensitivity
  // simulation. Quadratic interpolation needs costs only (measured: half the Jacobians).
  so.line_search_interpolation_type = ceres::QUADRATIC;
  so.num_threads = 1;  // the study runs trajectories in parallel
  so.minimizer_progress_to_stdout = false;
  so.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);

  result.success = summary.termination_type == ceres::CONVERGENCE || summary.termination_type == ceres::NO_CONVERGENCE;
  result.termination = fmt::format("{}: {}", ceres::TerminationTypeToString(summary.termination_type), summary.message);
  // Ceres' count: the steps computed (one linear solve each), the one that ended the solve
  // included.
  result.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
  result.jacobian_evaluations = summary.num_jacobian_evaluations;
  result.residual_evaluations = summary.num_residual_evaluations;
}

}  // namespace symoro::identify::detail
