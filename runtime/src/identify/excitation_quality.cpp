#include "symoro/identify/excitation_quality.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <Eigen/SVD>

namespace symoro::identify {

ExcitationQuality excitation_quality(const Eigen::MatrixXd& W, const std::vector<ParameterInfo>& parameters, int top) {
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
  const Eigen::VectorXd sigma = Eigen::JacobiSVD<Eigen::MatrixXd>(W).singularValues();
  if (sigma(sigma.size() - 1) > 0) q.kappa = sigma(0) / sigma(sigma.size() - 1);
  if (!q.unexcited.empty()) return q;
  const Eigen::MatrixXd Ws = W * norms.cwiseInverse().asDiagonal();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Ws, Eigen::ComputeThinV);
  const Eigen::VectorXd s = svd.singularValues();
  q.sigma_min_scaled = s(s.size() - 1);
  if (q.sigma_min_scaled > 0) {
    q.kappa_scaled = s(0) / q.sigma_min_scaled;
    q.log_det_scaled = 2 * s.array().log().sum();
  }
  const Eigen::VectorXd v = svd.matrixV().col(svd.matrixV().cols() - 1);
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
