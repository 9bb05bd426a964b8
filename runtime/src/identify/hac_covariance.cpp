#include "symoro/identify/hac_covariance.hpp"

#include <algorithm>

#include <Eigen/Cholesky>

namespace symoro::identify {

int residual_lags(const Eigen::VectorXd& e, const std::vector<int>& segment, int joints) {
  const int N = static_cast<int>(segment.size());
  const Eigen::Map<const Eigen::MatrixXd> E(e.data(), joints, N);
  const Eigen::VectorXd var = E.rowwise().squaredNorm();
  const int most = std::max(1, N / 10);
  for (int l = 1; l <= most; ++l) {
    double rho = 0;
    for (int j = 0; j < joints; ++j) {
      if (!(var(j) > 0)) continue;
      double c = 0;
      for (int k = l; k < N; ++k)
        if (segment[static_cast<std::size_t>(k)] == segment[static_cast<std::size_t>(k - l)])
          c += E(j, k) * E(j, k - l);
      rho += c / var(j) / joints;
    }
    if (rho < 0.05) return std::min(most, 2 * l);
  }
  return most;
}

Eigen::MatrixXd hac_covariance(const Eigen::MatrixXd& X, const Eigen::VectorXd& e, const std::vector<int>& segment,
                               int joints, int lags) {
  const int N = static_cast<int>(segment.size()), r = static_cast<int>(X.cols());
  Eigen::MatrixXd scores(r, N);
  for (int k = 0; k < N; ++k)
    scores.col(k) = X.middleRows(static_cast<Eigen::Index>(k) * joints, joints).transpose() *
                    e.segment(static_cast<Eigen::Index>(k) * joints, joints);
  Eigen::MatrixXd S = scores * scores.transpose();
  for (int l = 1; l <= lags; ++l) {
    const double w = 1 - static_cast<double>(l) / (lags + 1);
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(r, r);
    for (int k = l; k < N; ++k)
      if (segment[static_cast<std::size_t>(k)] == segment[static_cast<std::size_t>(k - l)])
        G.noalias() += scores.col(k) * scores.col(k - l).transpose();
    S += w * (G + G.transpose());
  }
  const Eigen::MatrixXd Bi = (X.transpose() * X).ldlt().solve(Eigen::MatrixXd::Identity(r, r));
  return Bi * S * Bi;
}

}  // namespace symoro::identify
