#include "symoro/identify/least_squares.hpp"

#include "symoro/identify/detail/singular_values.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/QR>
#include <Eigen/SVD>
#include <fmt/format.h>

namespace symoro::identify {

namespace detail {

Eigen::VectorXd tall_singular_values(const Eigen::MatrixXd& W) {
  if (W.rows() < W.cols()) return Eigen::JacobiSVD<Eigen::MatrixXd>(W).singularValues();
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(W);
  const Eigen::MatrixXd R = qr.matrixQR().topRows(W.cols()).triangularView<Eigen::Upper>();
  return Eigen::JacobiSVD<Eigen::MatrixXd>(R).singularValues();
}

}  // namespace detail

namespace {

struct Solve {
  Eigen::VectorXd phi, std_dev;
  Eigen::MatrixXd information;
};

// Least squares through Householder QR, and the covariance from R: (W'W)^-1 = R^-1 R^-T.
Solve solve(const Eigen::MatrixXd& W, const Eigen::VectorXd& y) {
  const Eigen::Index p = W.cols(), m = W.rows();
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(W);
  const Eigen::MatrixXd R = qr.matrixQR().topRows(p).triangularView<Eigen::Upper>();
  for (Eigen::Index i = 0; i < p; ++i)
    if (!(std::abs(R(i, i)) > 1e-12 * std::abs(R(0, 0))))
      throw std::invalid_argument(
          fmt::format("the regressor is rank deficient at column {} (parameter not excited)", i));
  Solve s;
  const Eigen::VectorXd qty = (qr.householderQ().transpose() * y).head(p);
  s.phi = R.triangularView<Eigen::Upper>().solve(qty);
  const double sigma2 = (y - W * s.phi).squaredNorm() / static_cast<double>(m - p);
  const Eigen::MatrixXd Rinv = R.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(p, p));
  s.std_dev = (sigma2 * Rinv.rowwise().squaredNorm()).cwiseSqrt();
  s.information = (R.transpose() * R) / sigma2;
  return s;
}

}  // namespace

double condition_number(const Eigen::MatrixXd& W, bool unit_columns) {
  if (W.rows() < W.cols() || W.cols() == 0) throw std::invalid_argument("condition_number: fewer rows than columns");
  Eigen::VectorXd sv;
  if (unit_columns) {
    Eigen::VectorXd norms = W.colwise().norm().transpose();
    for (Eigen::Index i = 0; i < norms.size(); ++i)
      if (norms(i) == 0) return std::numeric_limits<double>::infinity();
    sv = detail::tall_singular_values(W * norms.cwiseInverse().asDiagonal());
  } else {
    sv = detail::tall_singular_values(W);
  }
  return sv(sv.size() - 1) > 0 ? sv(0) / sv(sv.size() - 1) : std::numeric_limits<double>::infinity();
}

LeastSquaresResult least_squares(const Regression& r, const LeastSquaresOptions& options) {
  const Eigen::Index p = r.W.cols(), m = r.W.rows();
  if (m <= p) throw std::invalid_argument(fmt::format("least squares: {} rows for {} parameters", m, p));
  if (r.y.size() != m || r.joints <= 0 || m % r.joints != 0)
    throw std::invalid_argument("least squares: rows of W and y disagree with the joint count");
  for (Eigen::Index i = 0; i < p; ++i)
    if (r.W.col(i).cwiseAbs().maxCoeff() == 0)
      throw std::invalid_argument(fmt::format("the regressor's column {} is zero (parameter not excited)", i));

  LeastSquaresResult out;
  out.rows = static_cast<int>(m);
  out.kappa = condition_number(r.W);
  out.kappa_scaled = condition_number(r.W, true);
  out.weights = Eigen::VectorXd::Ones(r.joints);
  out.weighted = options.weighted;

  auto joint_rms = [&](const Eigen::VectorXd& phi) {
    const Eigen::VectorXd e = r.y - r.W * phi;
    Eigen::VectorXd rms = Eigen::VectorXd::Zero(r.joints);
    for (Eigen::Index k = 0; k < m; ++k) rms(k % r.joints) += e(k) * e(k);
    return (rms / static_cast<double>(m / r.joints)).cwiseSqrt().eval();
  };

  Solve s = solve(r.W, r.y);
  if (options.weighted) {
    for (int it = 0; it < options.wls_iterations; ++it) {
      const Eigen::VectorXd sigma = joint_rms(s.phi);
      for (int j = 0; j < r.joints; ++j) out.weights(j) = sigma(j) > 0 ? 1.0 / sigma(j) : 1.0;
      Eigen::VectorXd row_w(m);
      for (Eigen::Index k = 0; k < m; ++k) row_w(k) = out.weights(k % r.joints);
      s = solve(row_w.asDiagonal() * r.W, row_w.cwiseProduct(r.y));
    }
  }
  out.phi = s.phi;
  out.std_dev = s.std_dev;
  out.information = std::move(s.information);
  out.joint_rms = joint_rms(s.phi);
  out.residual_rms = std::sqrt(out.joint_rms.squaredNorm() / r.joints);
  return out;
}

}  // namespace symoro::identify
