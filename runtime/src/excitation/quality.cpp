#include "symoro/excitation/quality.hpp"

#include "symoro/identify/detail/singular_values.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>

namespace symoro::excitation {

namespace {

// The parameters whose column is (numerically) zero.
std::vector<std::string> unexcited_columns(const Eigen::VectorXd& norms, const std::vector<ParameterInfo>& parameters) {
  std::vector<std::string> names;
  const double largest = norms.size() > 0 ? norms.maxCoeff() : 0.0;
  for (Eigen::Index c = 0; c < norms.size(); ++c)
    if (!(norms(c) > 1e-14 * largest)) names.push_back(parameters[static_cast<std::size_t>(c)].name);
  return names;
}

// The `top` largest components of a direction in parameter space, named.
std::vector<std::pair<std::string, double>> largest_components(const Eigen::VectorXd& v,
                                                               const std::vector<ParameterInfo>& parameters, int top) {
  std::vector<int> order(static_cast<std::size_t>(v.size()));
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return std::abs(v(a)) > std::abs(v(b)); });
  std::vector<std::pair<std::string, double>> named;
  for (int i = 0; i < std::min<int>(top, static_cast<int>(order.size())); ++i)
    named.emplace_back(parameters[static_cast<std::size_t>(order[i])].name, v(order[i]));
  return named;
}

}  // namespace

bool numerically_singular(const Eigen::VectorXd& sigma) {
  return sigma.size() == 0 || !(sigma(sigma.size() - 1) >
                                static_cast<double>(sigma.size()) * std::numeric_limits<double>::epsilon() * sigma(0));
}

ExcitationQuality excitation_quality(const Eigen::MatrixXd& W, const std::vector<ParameterInfo>& parameters, int top,
                                     bool raw_kappa) {
  if (static_cast<std::size_t>(W.cols()) != parameters.size())
    throw std::invalid_argument("excitation_quality: " + std::to_string(W.cols()) + " columns for " +
                                std::to_string(parameters.size()) + " parameters");
  ExcitationQuality q;
  q.rows = static_cast<int>(W.rows());
  if (W.rows() < W.cols() || W.cols() == 0) return q;
  const Eigen::VectorXd norms = W.colwise().norm().transpose();
  q.unexcited = unexcited_columns(norms, parameters);
  if (raw_kappa) {
    const Eigen::VectorXd sigma = identify::detail::tall_singular_values(W);
    if (!numerically_singular(sigma)) q.kappa = sigma(0) / sigma(sigma.size() - 1);  // as the factor path judges it
  }
  if (!q.unexcited.empty()) return q;
  // The scaled quantities from the Gram matrix of the unit columns (parameters x parameters:
  // cheap for a study's 10^5-row W): its eigenvalues are the scaled sigma^2, exact to ~1e-16 of
  // the largest, so kappa_scaled keeps ~kappa_scaled^2 1e-16 of relative error.
  const Eigen::VectorXd inverse = norms.cwiseInverse();
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(W.cols(), W.cols());
  G.selfadjointView<Eigen::Lower>().rankUpdate((W * inverse.asDiagonal()).transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(G.selfadjointView<Eigen::Lower>());
  const Eigen::VectorXd lambda = eigen.eigenvalues();  // ascending
  q.sigma_min_scaled = std::sqrt(std::max(lambda(0), 0.0));
  if (lambda(0) > 0) {
    q.kappa_scaled = std::sqrt(lambda(lambda.size() - 1) / lambda(0));
    q.log_det_scaled = lambda.array().log().sum();
  }
  q.weakest = largest_components(eigen.eigenvectors().col(0), parameters, top);
  return q;
}

Eigen::MatrixXd triangular_factor(const Eigen::MatrixXd& W) {
  constexpr Eigen::Index kBlockRows = 2048;
  const Eigen::Index p = W.cols();
  Eigen::MatrixXd R(0, p), stacked;
  for (Eigen::Index at = 0; at < W.rows(); at += kBlockRows) {
    const Eigen::Index m = std::min(kBlockRows, W.rows() - at);
    stacked.resize(R.rows() + m, p);
    stacked.topRows(R.rows()) = R;
    stacked.bottomRows(m) = W.middleRows(at, m);
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(stacked);
    R = qr.matrixQR().topRows(std::min(stacked.rows(), p)).triangularView<Eigen::Upper>();
  }
  return R;
}

ExcitationQuality excitation_quality_of_factor(const Eigen::MatrixXd& R, Eigen::Index rows,
                                               const std::vector<ParameterInfo>& parameters, int top) {
  if (static_cast<std::size_t>(R.cols()) != parameters.size())
    throw std::invalid_argument("excitation_quality: " + std::to_string(R.cols()) + " columns for " +
                                std::to_string(parameters.size()) + " parameters");
  ExcitationQuality q;
  q.rows = static_cast<int>(rows);
  if (rows < R.cols() || R.cols() == 0 || R.rows() < R.cols()) return q;
  const Eigen::VectorXd norms = R.colwise().norm().transpose();  // W's column norms: Q keeps lengths
  q.unexcited = unexcited_columns(norms, parameters);
  const Eigen::VectorXd sigma = Eigen::JacobiSVD<Eigen::MatrixXd>(R).singularValues();
  if (!numerically_singular(sigma)) q.kappa = sigma(0) / sigma(sigma.size() - 1);
  if (!q.unexcited.empty()) return q;
  const Eigen::JacobiSVD<Eigen::MatrixXd> scaled(R * norms.cwiseInverse().asDiagonal(), Eigen::ComputeThinV);
  const Eigen::VectorXd s = scaled.singularValues();  // descending
  q.sigma_min_scaled = s(s.size() - 1);
  if (!numerically_singular(s)) {
    q.kappa_scaled = s(0) / q.sigma_min_scaled;
    q.log_det_scaled = 2 * s.array().log().sum();
  }
  q.weakest = largest_components(scaled.matrixV().col(s.size() - 1), parameters, top);
  return q;
}

preprocess::Samples reference_samples(const trajectory::SampledReference& reference, double interval) {
  const int step = std::max(1, static_cast<int>(std::lround(interval / reference.period)));
  const int rows = (reference.cycles() + step - 1) / step;
  const int n = reference.joints();
  preprocess::Samples s;
  s.interval = step * reference.period;
  s.time.resize(rows);
  s.q.resize(rows, n);
  s.qd.resize(rows, n);
  s.qdd.resize(rows, n);
  s.tau = Eigen::MatrixXd::Zero(rows, n);
  s.piece.assign(static_cast<std::size_t>(rows), 0);
  for (int k = 0; k < rows; ++k) {
    s.time(k) = k * s.interval;
    s.q.row(k) = reference.q.col(k * step).transpose();
    s.qd.row(k) = reference.qd.col(k * step).transpose();
    s.qdd.row(k) = reference.qdd.col(k * step).transpose();
  }
  return s;
}

ExcitationQuality excitation_quality(const identify::IdentificationModel& model,
                                     const trajectory::SampledReference& reference, double interval, int top) {
  const identify::ModelDescription& d = model.description();
  if (reference.joints() != d.nq)
    throw std::invalid_argument("excitation_quality: " + reference.name + " has " + std::to_string(reference.joints()) +
                                " joints, the model " + std::to_string(d.nq));
  const preprocess::Samples s = reference_samples(reference, interval);
  return excitation_quality(model.stack_regression(s).W, d.parameters, top);
}

}  // namespace symoro::excitation
