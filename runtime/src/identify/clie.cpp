// CLIE (clie.hpp) for any model's closed loop: the sample grid and filter, the bounds, the cost
// whose one block holds every residual, and the Ceres solve. Compiled once for every robot.
#include <algorithm>
#include <cmath>
#include <array>
#include <chrono>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <ceres/cost_function.h>
#include <ceres/iteration_callback.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/solver.h>
#include <fmt/format.h>

#include "symoro/identify/detail/clie_model.hpp"
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
      throw std::invalid_argument(
          fmt::format("CLIE: sample {} at t = {} s is not one of the simulation's cycles 0..{} of {} s", s,
                      measured.time(s), cycles - 1, period));
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
    throw std::invalid_argument(
        fmt::format("CLIE: the control period {} s differs from the preprocessing base period {} s", period, base));
  const double cutoff = std::min(o.derivative_cutoff, o.anti_alias_fraction * 0.5 / measured.interval);
  if (measured.report.cutoff > 0 && !(std::abs(measured.report.cutoff - cutoff) <= 1e-9 * cutoff))
    throw std::invalid_argument(fmt::format(
        "CLIE: the measured samples were filtered at {} Hz, the options give {} Hz (pass the preprocessing options)",
        measured.report.cutoff, cutoff));
  grid.sections = preprocess::butterworth_lowpass(o.filter_order, cutoff, 1 / period);
  grid.padding = preprocess::zero_phase_padding(grid.sections);
  if (grid.padding >= cycles)
    throw std::invalid_argument(
        fmt::format("CLIE: {} simulated cycles are too few for the {:.3g} Hz filter's padding of {}", cycles, cutoff,
                    grid.padding));
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

Bounds parameter_bounds(const Eigen::VectorXd& phi0, const std::vector<bool>& rotor_inertia,
                        const ClieOptions& options) {
  if (!(options.bound_factor >= 0) || !(options.min_bound > 0) || !(options.min_rotor_inertia >= 0))
    throw std::invalid_argument("CLIE: bound_factor >= 0, min_bound > 0 and min_rotor_inertia >= 0 needed");
  if (!phi0.allFinite()) throw std::invalid_argument("CLIE: the starting phi is not finite");
  if (!(options.std_bound >= 0)) throw std::invalid_argument("CLIE: std_bound must be >= 0");
  if (!(options.noise_floor >= 0) || !std::isfinite(options.noise_floor))
    throw std::invalid_argument("CLIE: noise_floor must be finite and >= 0");
  const bool by_std = options.std_bound > 0;
  if (by_std &&
      (options.scale.size() != phi0.size() || !(options.scale.array() > 0).all() || !options.scale.allFinite()))
    throw std::invalid_argument(fmt::format("CLIE: std_bound needs {} positive standard deviations, got {}",
                                            phi0.size(), options.scale.size()));
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

namespace {

// The noise-floor stop (ClieOptions::noise_floor), after each step taken: Ceres' own function
// tolerance also ends the solve on a rejected step, whose small cost change says nothing about
// the distance to the optimum.
class NoiseFloorStop final : public ceres::IterationCallback {
 public:
  NoiseFloorStop(double noise_floor, double degrees_of_freedom) : floor_(noise_floor), dof_(degrees_of_freedom) {}

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    if (s.iteration == 0 || !s.step_is_successful) return ceres::SOLVER_CONTINUE;
    const double variance = 2 * s.cost / dof_;  // at the new point
    if (!(s.cost_change < floor_ * variance)) return ceres::SOLVER_CONTINUE;
    message_ = fmt::format("noise floor reached. cost_change: {:e} < {} sigma^2 = {:e} (sigma^2 = 2 cost / {})",
                           s.cost_change, floor_, floor_ * variance, dof_);
    return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
  }
  const std::string& message() const { return message_; }

 private:
  double floor_, dof_;
  std::string message_;
};

// Ends a round of the solve when a step taken puts a free parameter on its bound
// (ClieOptions::hold_at_bounds). Reads the parameters Ceres writes back after every iteration.
class BoundReached final : public ceres::IterationCallback {
 public:
  BoundReached(const double* phi, const Bounds& bounds, const std::vector<bool>& held)
      : phi_(phi), bounds_(bounds), held_(held) {}

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override {
    if (s.iteration == 0 || !s.step_is_successful) return ceres::SOLVER_CONTINUE;
    for (std::size_t i = 0; i < held_.size(); ++i) {
      const auto k = static_cast<Eigen::Index>(i);
      if (!held_[i] && (phi_[i] <= bounds_.lower(k) || phi_[i] >= bounds_.upper(k)))
        reached_.push_back(static_cast<int>(i));
    }
    return reached_.empty() ? ceres::SOLVER_CONTINUE : ceres::SOLVER_TERMINATE_SUCCESSFULLY;
  }
  const std::vector<int>& reached() const { return reached_; }

 private:
  const double* phi_;
  const Bounds& bounds_;
  const std::vector<bool>& held_;
  std::vector<int> reached_;
};

// The cost with its last Jacobian kept: a round that a bound ends has evaluated the Jacobian
// at its end point, where the next round starts and Ceres asks for it again (one sensitivity
// simulation saved per held bound; the numbers served are the ones computed).
class LastJacobian final : public ceres::CostFunction {
 public:
  explicit LastJacobian(ceres::CostFunction& cost) : cost_(cost) {
    set_num_residuals(cost.num_residuals());
    *mutable_parameter_block_sizes() = cost.parameter_block_sizes();
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const Eigen::Index n = parameter_block_sizes()[0], m = num_residuals();
    const Eigen::Map<const Eigen::VectorXd> phi(parameters[0], n);
    const bool jacobian = jacobians && jacobians[0];
    if (jacobian && kept_ && phi_ == phi) {
      Eigen::Map<Eigen::VectorXd>(residuals, m) = residuals_;
      Eigen::Map<Eigen::VectorXd>(jacobians[0], m * n) = jacobian_;
      ++served_;
      return true;
    }
    const bool ok = cost_.Evaluate(parameters, residuals, jacobians);
    if (jacobian) {
      kept_ = ok;
      if (ok) {
        phi_ = phi;
        residuals_ = Eigen::Map<const Eigen::VectorXd>(residuals, m);
        jacobian_ = Eigen::Map<const Eigen::VectorXd>(jacobians[0], m * n);
      }
    }
    return ok;
  }
  int served() const { return served_; }  // Jacobians served from the kept one
  // The cost's gradient J'r at phi when the kept Jacobian is phi's (Ceres evaluates it at every
  // point it accepts, so at the end point of a solve).
  bool gradient(const Eigen::VectorXd& phi, Eigen::VectorXd& g) const {
    if (!kept_ || phi_ != phi) return false;
    const Eigen::Index n = phi.size(), m = num_residuals();
    const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> j(jacobian_.data(),
                                                                                                     m, n);
    g = j.transpose() * residuals_;
    return true;
  }

 private:
  ceres::CostFunction& cost_;
  mutable bool kept_ = false;
  mutable int served_ = 0;
  mutable Eigen::VectorXd phi_, residuals_, jacobian_;
};

}  // namespace

void solve_bounded(ceres::CostFunction& cost, const Bounds& bounds, const ClieOptions& options, ClieResult& result) {
  const int np = static_cast<int>(result.phi.size());
  double* phi = result.phi.data();
  const double dof = static_cast<double>(cost.num_residuals()) - np;
  std::vector<bool> held(static_cast<std::size_t>(np), false);
  result.iterations = result.jacobian_evaluations = result.residual_evaluations = 0;
  LastJacobian kept(cost);
  // Rounds: each a Ceres solve from where the last ended, with the parameters that reached a bound
  // held constant; a round ends when another reaches one. After each round, a held parameter
  // that the gradient pulls back into the box is released. Every round restarts the trust region
  // (its starting Jacobian is the one kept from the last round's end).
  for (;;) {
    ceres::Problem::Options po;
    po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(po);
    problem.AddResidualBlock(&kept, nullptr, phi);
    for (int i = 0; i < np; ++i) {
      problem.SetParameterLowerBound(phi, i, bounds.lower(i));
      problem.SetParameterUpperBound(phi, i, bounds.upper(i));
    }
    std::vector<int> constant;
    for (int i = 0; i < np; ++i)
      if (held[static_cast<std::size_t>(i)]) constant.push_back(i);
    if (static_cast<int>(constant.size()) == np) break;                                        // nothing left to move
    if (!constant.empty()) problem.SetManifold(phi, new ceres::SubsetManifold(np, constant));  // owned by problem

    ceres::Solver::Options so;
    so.minimizer_type = ceres::TRUST_REGION;
    so.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
    // The step's linear solve is negligible next to the simulations (AG02 at 40 ms: 0.1 s of
    // 16 s with QR, 0.03 s with the normal equations, same result), so the better-conditioned QR.
    so.linear_solver_type = ceres::DENSE_QR;
    so.max_num_iterations = options.max_iterations - result.iterations;
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
    so.update_state_every_iteration = options.hold_at_bounds;  // for BoundReached
    NoiseFloorStop noise_floor(options.noise_floor, dof);
    if (options.noise_floor > 0 && dof > 0) so.callbacks.push_back(&noise_floor);
    BoundReached bound_reached(phi, bounds, held);
    if (options.hold_at_bounds) so.callbacks.push_back(&bound_reached);
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);

    const bool user_stop = summary.termination_type == ceres::USER_SUCCESS;
    const bool noise_stop = user_stop && !noise_floor.message().empty();
    const bool new_bound = user_stop && !noise_stop;
    // Ceres' count: the steps computed (one linear solve each), the one that ended the solve
    // included. Iteration 0 counts as a successful step; a step that ends the solve by Ceres'
    // tolerances does not, one that a callback ends does.
    result.iterations += summary.num_successful_steps + summary.num_unsuccessful_steps - (user_stop ? 1 : 0);
    result.jacobian_evaluations += summary.num_jacobian_evaluations;
    result.residual_evaluations += summary.num_residual_evaluations;
    result.success = summary.termination_type == ceres::CONVERGENCE ||
                     summary.termination_type == ceres::NO_CONVERGENCE || user_stop;
    result.termination =
        noise_stop ? "CONVERGENCE: " + noise_floor.message()
                   : fmt::format("{}: {}", ceres::TerminationTypeToString(summary.termination_type), summary.message);
    for (int i : bound_reached.reached()) held[static_cast<std::size_t>(i)] = true;
    // Release a held parameter whose gradient points into the box (the cost falls moving it off
    // its bound): another round then moves it.
    bool released = false;
    Eigen::VectorXd g;
    if (std::find(held.begin(), held.end(), true) != held.end() && kept.gradient(result.phi, g))
      for (int i = 0; i < np; ++i) {
        const auto k = static_cast<std::size_t>(i);
        if (held[k] &&
            ((result.phi(i) <= bounds.lower(i) && g(i) < 0) || (result.phi(i) >= bounds.upper(i) && g(i) > 0))) {
          held[k] = false;
          released = true;
        }
      }
    if (!new_bound && !released) break;
    if (result.iterations >= options.max_iterations) {
      result.termination = fmt::format(
          "NO_CONVERGENCE: Maximum number of iterations reached. Number of iterations: {}.", result.iterations);
      break;
    }
  }
  result.jacobian_evaluations -= kept.served();  // sensitivity simulations
  result.held.clear();
  for (int i = 0; i < np; ++i)
    if (held[static_cast<std::size_t>(i)]) result.held.push_back(i);
}

// d tau / d phi at the sample rows, low-passed as the measurement when the grid filters, taken
// from the simulation row by row (preprocess::SampledZeroPhase): never stored for every cycle
// (cycles x n np doubles, 290 MB for AG02 on the reduced model).
class SampledSensitivities final : public ClosedLoop::SensitivityRows {
 public:
  SampledSensitivities(const SampleGrid& grid, Eigen::Index cycles, Eigen::Index width) : grid_(grid), width_(width) {
    if (grid.filter) {
      filter_.emplace(grid.sections, grid.padding, cycles, width, grid.rows);
    } else {
      order_.resize(grid.rows.size());
      for (std::size_t s = 0; s < order_.size(); ++s) order_[s] = s;
      std::stable_sort(order_.begin(), order_.end(),
                       [&](std::size_t a, std::size_t b) { return grid.rows[a] < grid.rows[b]; });
      rows_.resize(static_cast<Eigen::Index>(grid.rows.size()), width);
    }
  }
  void row(const double* d) override {
    if (filter_) {
      filter_->push(d);
    } else {
      for (; next_ < order_.size() && grid_.rows[order_[next_]] == k_; ++next_)
        rows_.row(static_cast<Eigen::Index>(order_[next_])) = Eigen::Map<const Eigen::RowVectorXd>(d, width_);
    }
    ++k_;
  }
  // Row s: the sample's d tau / d phi (after a complete simulation).
  const preprocess::Channels& finish() {
    if (filter_) filter_->finish(rows_);
    return rows_;
  }

 private:
  const SampleGrid& grid_;
  Eigen::Index width_, k_ = 0;
  std::optional<preprocess::SampledZeroPhase> filter_;
  std::vector<std::size_t> order_;
  std::size_t next_ = 0;
  preprocess::Channels rows_;
};

// All residuals tau_m - tau_s at the samples (sample-major, joint fastest) in one block of
// np parameters; its Jacobian, -(filtered d tau_s / d phi) at the sample rows, is one row of
// the simulation's dtau per sample. A diverging simulation fails the evaluation, which Ceres
// takes as a rejected step.
class ClieCost final : public ceres::CostFunction {
 public:
  ClieCost(const ClosedLoop& sim, const preprocess::Samples& measured, const SampleGrid& grid)
      : sim_(sim), measured_(measured), grid_(grid), n_(sim.joints()), np_(sim.parameters()) {
    set_num_residuals(static_cast<int>(grid.rows.size()) * n_);
    mutable_parameter_block_sizes()->push_back(np_);
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
    Eigen::VectorXd phi;
    bool ok = false;
    Divergence why;
    Eigen::VectorXd residuals;
  };

  bool evaluate(const double* phi_data, double* residuals, double* jacobian, Divergence* why) const {
    const Eigen::Map<const Eigen::VectorXd> phi(phi_data, np_);
    const Eigen::Index count = num_residuals();
    if (!jacobian)
      for (const Evaluated& e : evaluated_)
        if (e.residuals.size() == count && e.phi.size() == phi.size() && e.phi == phi) {
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

  bool simulate_residuals(const Eigen::VectorXd& phi, double* residuals, double* jacobian, Divergence* why) const {
    std::optional<SampledSensitivities> dtau;
    if (jacobian) {
      dtau.emplace(grid_, sim_.cycles(), static_cast<Eigen::Index>(n_) * np_);
      if (!sim_.simulate(phi, tau_, *dtau, why)) return false;
    } else if (!sim_.simulate(phi, tau_, nullptr, why)) {
      return false;
    }
    lowpass(grid_, tau_);
    const Eigen::Index samples = static_cast<Eigen::Index>(grid_.rows.size());
    for (Eigen::Index s = 0; s < samples; ++s)
      for (int j = 0; j < n_; ++j) residuals[s * n_ + j] = measured_.tau(s, j) - tau_(grid_.rows[s], j);
    if (jacobian) {
      const preprocess::Channels& d = dtau->finish();
      // A row is d tau_j / d phi_i at j * np + i: the sample's n Jacobian rows, row-major.
      Eigen::Map<preprocess::Channels>(jacobian, samples, static_cast<Eigen::Index>(n_) * np_) = -d;
    }
    return true;
  }

  const ClosedLoop& sim_;
  const preprocess::Samples& measured_;
  const SampleGrid& grid_;
  const int n_, np_;
  mutable preprocess::Channels tau_;  // reused between evaluations
  mutable int rejected_ = 0;
  mutable std::array<Evaluated, 2> evaluated_;
  mutable std::size_t next_slot_ = 0;
};

}  // namespace symoro::identify::detail

namespace symoro::identify {
namespace {

void check_clie_inputs(const ClosedLoop& sim, const preprocess::Samples& measured, const Eigen::VectorXd& phi) {
  if (phi.size() != sim.parameters())
    throw std::invalid_argument("CLIE: phi has " + std::to_string(phi.size()) + " entries, the model " +
                                std::to_string(sim.parameters()));
  if (measured.tau.cols() != sim.joints() || measured.tau.rows() != measured.time.size())
    throw std::invalid_argument("CLIE: the measured samples need time and an " + std::to_string(sim.joints()) +
                                "-joint tau of as many rows");
}

}  // namespace

bool simulated_samples(const ClosedLoop& sim, const preprocess::Samples& measured, const Eigen::VectorXd& phi,
                       const ClieOptions& options, Eigen::MatrixXd& tau, Divergence* why) {
  check_clie_inputs(sim, measured, phi);
  const detail::SampleGrid grid = detail::sample_grid(measured, sim.period(), sim.cycles(), options);
  preprocess::Channels simulated;
  if (!sim.simulate(phi, simulated, nullptr, why)) return false;
  detail::lowpass(grid, simulated);
  tau.resize(static_cast<Eigen::Index>(grid.rows.size()), sim.joints());
  for (Eigen::Index s = 0; s < tau.rows(); ++s) tau.row(s) = simulated.row(grid.rows[s]);
  return true;
}

ClieResult clie(const ClosedLoop& sim, const preprocess::Samples& measured, const Eigen::VectorXd& phi0,
                const ClieOptions& options) {
  const auto wall0 = std::chrono::steady_clock::now();
  const auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count(); };
  check_clie_inputs(sim, measured, phi0);
  const int n = sim.joints(), np = sim.parameters();
  const detail::SampleGrid grid = detail::sample_grid(measured, sim.period(), sim.cycles(), options);
  std::vector<bool> rotor_inertia(static_cast<std::size_t>(np));
  for (int i = 0; i < np; ++i) rotor_inertia[i] = std::string(sim.parameter_info()[i].family) == "IA";
  const detail::Bounds bounds = detail::parameter_bounds(phi0, rotor_inertia, options);

  ClieResult result;
  result.phi = phi0.cwiseMax(bounds.lower).cwiseMin(bounds.upper);
  detail::ClieCost cost(sim, measured, grid);
  Eigen::VectorXd r;
  if (!cost.residuals(result.phi, r, &result.start_divergence)) {
    result.termination =
        "not started: the starting point's simulation diverges (" + result.start_divergence.describe() + ")";
    result.wall = elapsed();
    return result;
  }
  result.initial_cost = 0.5 * r.squaredNorm();
  result.rms_initial = detail::rms_per_joint(r, n);

  const Eigen::VectorXd start = result.phi;
  detail::solve_bounded(cost, bounds, options, result);
  result.rejected_divergent = cost.rejected();
  // Ceres ends on a point it evaluated successfully, so this cannot diverge; if it did, the
  // start is what remains valid.
  Divergence why;
  if (cost.residuals(result.phi, r, &why)) {
    result.final_cost = 0.5 * r.squaredNorm();
    result.rms_final = detail::rms_per_joint(r, n);
  } else {
    result.success = false;
    result.termination += "; the end point diverges (" + why.describe() + "), the start is kept";
    result.phi = start;
    result.final_cost = result.initial_cost;
    result.rms_final = result.rms_initial;
  }
  for (int i = 0; i < np; ++i)
    if (result.phi(i) <= bounds.lower(i) || result.phi(i) >= bounds.upper(i)) result.at_bound.push_back(i);
  result.wall = elapsed();
  return result;
}

}  // namespace symoro::identify
