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
  // sum_l w_l (G_l + G_l'), G_l = sum_k s_k s_{k-l}', as sum_k s_k u_k' (and its transpose) with
  // u_k = sum_{l=1..L} (1 - l / (L + 1)) s_{k-l} = A_k - B_k / (L + 1), A_k = sum s_{k-l} and
  // B_k = sum l s_{k-l} kept by sliding sums: O(N r) for any L, not O(N L r^2).
  Eigen::MatrixXd U = Eigen::MatrixXd::Zero(r, N);
  Eigen::VectorXd A = Eigen::VectorXd::Zero(r), B = Eigen::VectorXd::Zero(r);
  for (int k = 0, start = 0; k < N; ++k) {
    if (k > 0 && segment[static_cast<std::size_t>(k)] != segment[static_cast<std::size_t>(k - 1)]) {
      start = k;
      A.setZero();
      B.setZero();
    } else if (k > start) {
      // From k - 1 to k: B_k = s_{k-1} + B_{k-1} + A_{k-1} - (L + 1) s_{k-1-L}, A_k = A_{k-1} + s_{k-1} - s_{k-1-L}.
      const bool leaves = k - 1 - lags >= start;
      B += A + scores.col(k - 1);
      A += scores.col(k - 1);
      if (leaves) {
        B -= (lags + 1) * scores.col(k - 1 - lags);
        A -= scores.col(k - 1 - lags);
      }
    }
    U.col(k) = A - B / (lags + 1);
  }
  const Eigen::MatrixXd G = scores * U.transpose();
  const Eigen::MatrixXd S = scores * scores.transpose() + G + G.transpose();
  const Eigen::MatrixXd Bi = (X.transpose() * X).ldlt().solve(Eigen::MatrixXd::Identity(r, r));
  return Bi * S * Bi;
}

}  // namespace symoro::identify
