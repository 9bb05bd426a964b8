#include "pca.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

namespace symoro::study {

namespace {

bool usable(const Eigen::VectorXd& v, Eigen::Index p) { return v.size() == p && v.allFinite(); }

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  const size_t h = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + h, v.end());
  const double hi = v[h];
  if (v.size() % 2) return hi;
  return 0.5 * (hi + *std::max_element(v.begin(), v.begin() + h));
}

}  // namespace

PcaClouds pca_clouds(const std::vector<RunRecord>& runs, int components) {
  if (runs.empty()) throw std::invalid_argument("pca: no runs");
  Eigen::Index p = 0;  // from the first run that did not fail (a failed run has no vectors)
  for (const RunRecord& r : runs)
    if (!r.failed && r.phi_ols.size() > 0) {
      p = r.phi_ols.size();
      break;
    }
  std::vector<const Eigen::VectorXd*> pooled;
  for (const RunRecord& r : runs)
    for (const Eigen::VectorXd* v : {&r.phi_ols, &r.phi_sdp, &r.phi_clie})
      if (usable(*v, p)) pooled.push_back(v);
  if (pooled.size() < 2) throw std::invalid_argument("pca: fewer than two parameter vectors");

  PcaClouds c;
  c.mean = Eigen::VectorXd::Zero(p);
  for (const auto* v : pooled) c.mean += *v;
  c.mean /= static_cast<double>(pooled.size());
  Eigen::MatrixXd Z(static_cast<Eigen::Index>(pooled.size()), p);
  for (size_t i = 0; i < pooled.size(); ++i) Z.row(i) = (*pooled[i] - c.mean).transpose();
  c.scale = (Z.colwise().squaredNorm() / static_cast<double>(pooled.size() - 1)).cwiseSqrt().transpose();
  for (Eigen::Index i = 0; i < p; ++i)
    if (!(c.scale(i) > 0)) c.scale(i) = 1;  // a constant parameter carries no direction
  Z = Z * c.scale.cwiseInverse().asDiagonal();

  // Principal directions: eigenvectors of the pooled covariance, largest first.
  const Eigen::MatrixXd cov = Z.transpose() * Z / static_cast<double>(pooled.size() - 1);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(cov);
  const int k = static_cast<int>(std::min<Eigen::Index>(components, p));
  c.components.resize(p, k);
  c.explained.resize(k);
  const double total = eig.eigenvalues().sum();
  for (int i = 0; i < k; ++i) {
    Eigen::VectorXd d = eig.eigenvectors().col(p - 1 - i);
    // A deterministic sign: the largest entry positive.
    Eigen::Index at;
    d.cwiseAbs().maxCoeff(&at);
    if (d(at) < 0) d = -d;
    c.components.col(i) = d;
    c.explained(i) = total > 0 ? eig.eigenvalues()(p - 1 - i) / total : 0;
  }
  auto score = [&](const Eigen::VectorXd& v) -> Eigen::RowVectorXd {
    if (!usable(v, p)) return Eigen::RowVectorXd::Constant(k, std::numeric_limits<double>::quiet_NaN());
    return (((v - c.mean).cwiseQuotient(c.scale)).transpose() * c.components);
  };
  const Eigen::Index n = static_cast<Eigen::Index>(runs.size());
  c.ols.resize(n, k);
  c.sdp.resize(n, k);
  c.clie.resize(n, k);
  for (Eigen::Index i = 0; i < n; ++i) {
    c.ols.row(i) = score(runs[i].phi_ols);
    c.sdp.row(i) = score(runs[i].phi_sdp);
    c.clie.row(i) = score(runs[i].phi_clie);
  }
  return c;
}

Selection select_central(const std::vector<RunRecord>& runs, const PcaClouds& pca, double variance_fraction) {
  Selection s;
  const Eigen::Index available = pca.components.cols();
  double cumulative = 0;
  int k = 0;
  while (k < available && cumulative < variance_fraction) cumulative += pca.explained(k++);
  s.components = std::max(k, 1);
  // A run's final vector: CLIE's where it ran and succeeded, the SDP (or OLS) estimate where
  // CLIE did not run; never a failed run's.
  std::vector<int> candidates;
  bool any_clie = false;
  for (int i = 0; i < static_cast<int>(runs.size()); ++i) {
    const RunRecord& r = runs[i];
    if (r.failed || !(r.clie_ran ? r.clie_success : true) || !pca.clie.row(i).allFinite()) continue;
    candidates.push_back(i);
    any_clie = any_clie || r.clie_ran;
  }
  s.centrality.assign(runs.size(), std::numeric_limits<double>::infinity());
  if (candidates.empty()) {
    s.rule = "no run produced a final vector (CLIE failed or every run failed): nothing to select";
    return s;
  }
  Eigen::VectorXd centre(s.components), spread(s.components);
  for (int c = 0; c < s.components; ++c) {
    std::vector<double> x;
    for (int i : candidates) x.push_back(pca.clie(i, c));
    centre(c) = median(x);
    std::vector<double> dev;
    for (double v : x) dev.push_back(std::abs(v - centre(c)));
    spread(c) = 1.4826 * median(dev);
    if (!(spread(c) > 0)) spread(c) = 1;
  }
  double best = std::numeric_limits<double>::infinity();
  for (int i : candidates) {
    const Eigen::VectorXd d = (pca.clie.row(i).head(s.components).transpose() - centre).cwiseQuotient(spread);
    s.centrality[i] = d.norm();
    if (s.centrality[i] < best) {
      best = s.centrality[i];
      s.run = i;
    }
  }
  s.rule = fmt::format(
      "most central of {} {}: smallest distance to the cloud's median over the first {} principal "
      "scores ({:.0f} % of the pooled variance), each scaled by its robust spread (1.4826 MAD)",
      candidates.size(), any_clie ? "CLIE vectors" : "final vectors (SDP, or OLS where PD; CLIE not run)", s.components,
      100 * cumulative);
  return s;
}

double cloud_dispersion(const std::vector<Eigen::VectorXd>& cloud, const PcaClouds& pca) {
  std::vector<Eigen::VectorXd> z;
  for (const auto& v : cloud)
    if (usable(v, pca.mean.size())) z.push_back((v - pca.mean).cwiseQuotient(pca.scale));
  if (z.size() < 2) return 0;
  Eigen::VectorXd m = Eigen::VectorXd::Zero(pca.mean.size());
  for (const auto& v : z) m += v;
  m /= static_cast<double>(z.size());
  double trace = 0;
  for (const auto& v : z) trace += (v - m).squaredNorm();
  return trace / static_cast<double>(z.size() - 1);
}

}  // namespace symoro::study
