// Closed-loop input error (CLIE) refinement (paper eq. clie) with Ceres:
//   min_phi  sum_k | tau_m(t_k) - tau_s(t_k; phi) |^2
// over the target-grid samples of one sampling interval. tau_s comes from the closed-loop
// simulation (closed_loop.hpp) passed through the same zero-phase low-pass the measurement
// went through in preprocessing, so both sides see the same filter; the Jacobian is the
// simulation's forward sensitivities through that (linear) filter (closed_loop.hpp), no finite
// differences. Bounds: about +-bound_factor times each initial value, rotor inertias positive,
// a parameter that reaches its bound held there (ClieOptions::hold_at_bounds);
// optionally also +-std_bound standard deviations of the run's OLS estimate (`scale`), so that
// CLIE cannot wander far along directions its data barely sees (docs/identification.md).
// A trial point whose simulation diverges is rejected (Ceres shrinks its step); a starting
// point that diverges ends the refinement with a clear report.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "symoro/identify/closed_loop.hpp"
#include "symoro/preprocess/preprocess.hpp"

namespace symoro::identify {

struct ClieOptions {
  int max_iterations = 30;
  double function_tolerance = 1e-7;  // Ceres: relative change of the cost
  // The noise-floor stop (docs/identification.md): the solve also ends after a step that lowered
  // the cost by less than noise_floor sigma^2, sigma^2 = 2 cost / (m - p) the residual variance
  // at the new point (m residuals, p parameters). A Gauss-Newton step that lowers the cost by
  // sigma^2 / 2 changes the prediction by |J dphi| = sigma: one standard deviation of the
  // estimate in the data's metric: with 0.5, CLIE stops once its steps are shorter than the
  // estimate's own noise. Only steps taken count (a rejected step says nothing about the distance
  // to the optimum). Off by default (0: function_tolerance alone, the paper's rule): on the
  // twin's study 0.5 stopped PA07@10ms and PB09@20ms early, 182 and 36 sigma^2 above the
  // paper's end (docs/identification.md); the held bounds alone end the creep it was meant for.
  double noise_floor = 0;
  double parameter_tolerance = 1e-8;
  double gradient_tolerance = 1e-10;
  double bound_factor = 100;        // bounds phi0_i -+ bound_factor |phi0_i|
  double min_bound = 1e-4;          // bound half-width floor for phi0_i near 0 (in the parameter's unit)
  double min_rotor_inertia = 1e-6;  // kg m^2: lower bound of IA parameters
  // A parameter that a step puts on its bound is held there: Ceres is restarted with it
  // constant, and released (another restart) when the gradient at the end of a round pulls it
  // back into the box. Ceres' bounded Levenberg-Marquardt computes each step as if there were no
  // bounds and then projects it, so while a parameter presses on its bound the step's predicted
  // decrease counts a move that the projection cancels: steps are rejected or cut short and the
  // solve creeps (docs/identification.md: PB01 at 20 ms, 21 steps for 0.02 % of cost after the
  // first). false: Ceres' projection alone (as before).
  bool hold_at_bounds = true;
  // When std_bound > 0 and scale holds one value per parameter (the run's OLS standard
  // deviations): bounds phi0_i -+ std_bound scale_i as well, the tighter of the two applying.
  double std_bound = 0;
  Eigen::VectorXd scale;
  bool filter = true;              // the measurement's low-pass on tau_s (off: raw samples)
  preprocess::Options preprocess;  // must be the options that produced the measured samples
};

struct ClieResult {
  Eigen::VectorXd phi;
  bool success = false;                     // Ceres converged or hit max_iterations from a valid start
  Divergence start_divergence;              // set when the starting point's simulation diverges
  std::string termination;                  // Ceres' termination type and message
  double initial_cost = 0, final_cost = 0;  // 0.5 sum of squares, N^2 m^2
  int iterations = 0;
  int jacobian_evaluations = 0, residual_evaluations = 0, rejected_divergent = 0;
  Eigen::VectorXd rms_initial, rms_final;  // per joint torque error at the samples, N m
  std::vector<int> at_bound;               // parameters ending on a bound
  std::vector<int> held;                   // of those, the ones held there (ClieOptions::hold_at_bounds)
  double wall = 0;                         // s
};

// The simulated torque at the samples' grid (filtered as the measurement when options.filter):
// rows match measured.time. Returns false on divergence (fills *why).
bool simulated_samples(const ClosedLoop& sim, const preprocess::Samples& measured, const Eigen::VectorXd& phi,
                       const ClieOptions& options, Eigen::MatrixXd& tau, Divergence* why);

// CLIE from phi0 on one run's closed loop (any model: ClosedLoopSimulator<Model> for a generated
// one, closed_loop_model.hpp).
ClieResult clie(const ClosedLoop& sim, const preprocess::Samples& measured, const Eigen::VectorXd& phi0,
                const ClieOptions& options = {});

}  // namespace symoro::identify
