// The covariance of a least-squares estimate whose residual is correlated from sample to sample
// (Newey-West): (X'X)^-1 S (X'X)^-1, S the scores' long-run covariance with Bartlett weights.
// The filtered samples identification works on are not independent: a covariance that took them
// so (sigma^2 (X'X)^-1) claims several times too much. Rows come sample after sample, `joints`
// rows per sample; `segment` tells which log each sample belongs to (no lag crosses logs).
#pragma once

#include <vector>

#include <Eigen/Core>

namespace symoro::identify {

// The lag past which the residual is uncorrelated: the first lag where its autocorrelation,
// averaged over the joints, falls below 0.05, doubled (Bartlett's weights halve the terms near
// it); at most a tenth of the samples.
int residual_lags(const Eigen::VectorXd& residual, const std::vector<int>& segment, int joints);

// X: (samples * joints) x p, residual: its rows' residuals.
Eigen::MatrixXd hac_covariance(const Eigen::MatrixXd& X, const Eigen::VectorXd& residual,
                               const std::vector<int>& segment, int joints, int lags);

}  // namespace symoro::identify
