// OLS on the stacked regression (paper eq. ols) with the regressor's condition number and the
// parameters' standard deviations, and weighted least squares as an option: each joint's rows
// weighted by the inverse of that joint's residual standard deviation (Gautier's classic
// weighting: joints with noisier torque count less), re-estimated a few times.
#pragma once

#include <Eigen/Core>

#include "symoro/identify/regression.hpp"

namespace symoro::identify {

struct LeastSquaresOptions {
  bool weighted = false;   // WLS instead of OLS
  int wls_iterations = 3;  // weight re-estimations
};

struct LeastSquaresResult {
  Eigen::VectorXd phi;
  // sqrt(diag(sigma^2 (W'W)^-1)) with sigma^2 = |r|^2 / (rows - np) (weighted rows for WLS).
  Eigen::VectorXd std_dev;
  // W'W / sigma^2 (weighted rows for WLS): the inverse of the estimate's covariance.
  Eigen::MatrixXd information;
  double kappa = 0;           // sigma_max / sigma_min of W (unweighted, as the paper reports it)
  double kappa_scaled = 0;    // the same with unit-norm columns
  double residual_rms = 0;    // N m, of y - W phi over all rows
  Eigen::VectorXd joint_rms;  // per joint residual rms
  Eigen::VectorXd weights;    // per joint row weight (all 1 for OLS)
  int rows = 0;
  bool weighted = false;
};

// Throws std::invalid_argument when W has fewer rows than columns, or when a column is zero or
// W is numerically rank deficient (the parameter is not excited by this run): the message names
// the column.
LeastSquaresResult least_squares(const Regression& r, const LeastSquaresOptions& options = {});

// sigma_max / sigma_min, optionally after scaling the columns to unit norm.
double condition_number(const Eigen::MatrixXd& W, bool unit_columns = false);

}  // namespace symoro::identify
