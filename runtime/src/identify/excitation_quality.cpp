#include "symoro/identify/excitation_quality.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

namespace symoro::identify {

ExcitationQuality excitation_quality(const Eigen::MatrixXd& W, const std::vector<ParameterInfo>& parameters, int top,
                                     bool raw_kappa) {
  if (static_cast<std::size_t>(W.cols()) != parameters.size())
    throw std::invalid_argument("excitation_quality: " + std::to_string(W.cols()) + " columns for " +
                                std::to_string(parameters.size()) + " parameters");
  ExcitationQuality q;
  q.rows = static_cast<int>(W.rows());
  if (W.rows() < W.cols() || W.cols() == 0) return q;
  const Eigen::VectorXd norms = W.colwise().norm().transpose();
  const double largest = norms.maxCoeff();
  for (Eigen::Index c = 0; c < W.cols(); ++c)
    if (!(norms(c) > 1e-14 * largest)) q.unexcited.push_back(parameters[static_cast<std::size_t>(c)].name);
  if (raw_kappa) {
    const Eigen::VectorXd sigma = Eigen::JacobiSVD<Eigen::MatrixXd>(W).singularValues();
    if (sigma(sigma.size() - 1) > 0) q.kappa = sigma(0) / sigma(sigma.size() - 1);
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
  const Eigen::VectorXd v = eigen.eigenvectors().col(0);
  std::vector<int> order(static_cast<std::size_t>(v.size()));
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return std::abs(v(a)) > std::abs(v(b)); });
  for (int i = 0; i < std::min<int>(top, static_cast<int>(order.size())); ++i)
    q.weakest.emplace_back(parameters[static_cast<std::size_t>(order[i])].name, v(order[i]));
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

ExcitationQuality excitation_quality(const IdentificationModel& model, const trajectory::SampledReference& reference,
                                     double interval, int top) {
  const ModelDescription& d = model.description();
  if (reference.joints() != d.nq)
    throw std::invalid_argument("excitation_quality: " + reference.name + " has " + std::to_string(reference.joints()) +
                                " joints, the model " + std::to_string(d.nq));
  const preprocess::Samples s = reference_samples(reference, interval);
  return excitation_quality(model.stack_regression(s).W, d.parameters, top);
}

}  // namespace symoro::identify
