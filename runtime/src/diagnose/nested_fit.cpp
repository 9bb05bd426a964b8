// The selection's least squares (nested_fit.hpp).
#include "nested_fit.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

namespace symoro::diagnose::detail {

// Per-row weights (row s * n + j gets w_j).
Eigen::VectorXd row_weights(const DesignStack& d, const Eigen::VectorXd& w) {
  Eigen::VectorXd r(d.rows());
  for (int s = 0; s < d.samples(); ++s) r.segment(static_cast<Eigen::Index>(s) * d.joints, d.joints) = w;
  return r;
}

Eigen::MatrixXd per_sample(const DesignStack& d, const Eigen::VectorXd& stacked) {
  Eigen::MatrixXd m(d.samples(), d.joints);
  for (int s = 0; s < d.samples(); ++s)
    m.row(s) = stacked.segment(static_cast<Eigen::Index>(s) * d.joints, d.joints).transpose();
  return m;
}

Eigen::VectorXd joint_rms(const DesignStack& d, const Eigen::VectorXd& r) {
  const Eigen::MatrixXd m = per_sample(d, r);
  return (m.colwise().squaredNorm() / std::max(1, d.samples())).cwiseSqrt().transpose();
}

// The identified parameters the fit estimates: all of them, or none when they are held.
Eigen::Index free_parameters(const DesignStack& d) { return d.held() ? 0 : d.W.cols(); }

// The current model's design on a stack: W (unless its parameters are held), then each
// effect's columns (evaluated at `state`).
Eigen::MatrixXd design(const DesignStack& d, const std::vector<Candidate>& effects, const FitState& state) {
  const Eigen::Index np = free_parameters(d);
  Eigen::Index cols = np;
  std::vector<Eigen::MatrixXd> blocks;
  for (const auto& e : effects) {
    blocks.push_back(effect_columns(e, d, state));
    cols += blocks.back().cols();
  }
  Eigen::MatrixXd A(d.rows(), cols);
  A.leftCols(np) = d.W.leftCols(np);
  Eigen::Index c = np;
  for (const auto& b : blocks) {
    A.middleCols(c, b.cols()) = b;
    c += b.cols();
  }
  return A;
}

// Scales the columns of As to unit norm (zero columns stay) and returns the scales: the
// candidates' units differ by orders of magnitude.
Eigen::VectorXd unit_columns(Eigen::MatrixXd& As) {
  Eigen::VectorXd scale = As.colwise().norm().transpose();
  for (Eigen::Index i = 0; i < scale.size(); ++i) {
    if (!(scale(i) > 0)) scale(i) = 1;
    As.col(i) /= scale(i);
  }
  return scale;
}

Solve weighted_ls(const Eigen::MatrixXd& A, const Eigen::VectorXd& y, const Eigen::VectorXd& rw, double tau_int) {
  if (A.cols() == 0) return {};  // nothing to fit (held parameters, no effect)
  Eigen::MatrixXd As = rw.asDiagonal() * A;
  const Eigen::VectorXd scale = unit_columns(As);
  const Eigen::VectorXd ys = rw.cwiseProduct(y);
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(As);
  Solve s;
  s.beta = qr.solve(ys).cwiseQuotient(scale);
  const Eigen::VectorXd r = ys - As * qr.solve(ys);
  // Var(beta) ~ sigma^2 tau_int (A'WA)^-1: autocorrelated errors carry 1/tau_int of the
  // information of independent ones.
  const double sigma2 = r.squaredNorm() / std::max<double>(1.0, static_cast<double>(A.rows() - A.cols()));
  const Eigen::MatrixXd G = As.transpose() * As;
  const Eigen::MatrixXd Ginv = G.ldlt().solve(Eigen::MatrixXd::Identity(G.rows(), G.cols()));
  s.sd = (sigma2 * tau_int * Ginv.diagonal()).cwiseMax(0).cwiseSqrt().cwiseQuotient(scale);
  const Eigen::VectorXd inv = scale.cwiseInverse();
  s.cov = sigma2 * tau_int * (inv.asDiagonal() * Ginv * inv.asDiagonal());
  return s;
}

FitState state_of(const DesignStack& d, const Eigen::MatrixXd& A, const Eigen::VectorXd& beta, Eigen::Index np) {
  FitState f;
  f.tau_model = A * beta + d.tau0;
  f.phi = d.held() ? d.held_phi : Eigen::VectorXd(beta.head(np));
  return f;
}

FitState base_state(const DesignStack& d, const Eigen::VectorXd& phi) {
  FitState f;
  f.tau_model = d.held() ? d.tau0 : Eigen::VectorXd(d.W * phi + d.tau0);
  f.phi = d.held() ? d.held_phi : phi;
  return f;
}

bool linearized(const std::vector<Candidate>& effects) {
  for (const auto& e : effects)
    if (e.kind == EffectKind::TorqueConstant || e.kind == EffectKind::ActuationDelay || e.kind == EffectKind::Backlash)
      return true;
  return false;
}

double pooled_time(const Eigen::VectorXd& tau) { return tau.size() ? tau.mean() : 1.0; }

// Held-out weighted SSE of a fit on the joints in `on` (all when empty).
double heldout_sse(const Fit& f, const Eigen::VectorXd& weights, const std::vector<int>& on, int samples) {
  double sse = 0;
  for (Eigen::Index j = 0; j < f.heldout_rmse.size(); ++j)
    if (on.empty() || std::find(on.begin(), on.end(), static_cast<int>(j) + 1) != on.end())
      sse += std::pow(weights(j) * f.heldout_rmse(j), 2) * samples;
  return sse;
}

NestedDesign nested_design(const DesignStack& train, const DesignStack& heldout, const std::vector<Candidate>& effects,
                           const Fit& current, const Eigen::VectorXd& weights) {
  NestedDesign d;
  d.train = &train;
  d.heldout = &heldout;
  // The current design, refitted (so its residual is orthogonal to it); linearized columns
  // are evaluated about the current fit's torques.
  FitState st, sh;
  st.phi = sh.phi = current.phi;
  st.tau_model = current.train_tau;
  sh.tau_model = current.heldout_tau;
  d.A = design(train, effects, st);
  d.Ah = design(heldout, effects, sh);
  d.rw = row_weights(train, weights);
  d.rwh = row_weights(heldout, weights);
  const Eigen::VectorXd y = train.target(), yh = heldout.target();
  d.As = d.rw.asDiagonal() * d.A;
  d.scale = unit_columns(d.As);
  const Eigen::VectorXd ys = d.rw.cwiseProduct(y);
  // With held parameters and no effect yet the design is empty: the residual is y itself.
  d.empty = d.As.cols() == 0;
  const Eigen::VectorXd beta_s =
      d.empty ? Eigen::VectorXd() : Eigen::VectorXd(Eigen::ColPivHouseholderQR<Eigen::MatrixXd>(d.As).solve(ys));
  d.r = d.empty ? ys : Eigen::VectorXd(ys - d.As * beta_s);
  d.beta = beta_s.cwiseQuotient(d.scale);
  d.rh = d.rwh.cwiseProduct(d.empty ? yh : Eigen::VectorXd(yh - d.Ah * d.beta));
  d.Gf.compute(d.empty ? Eigen::MatrixXd::Identity(1, 1) : Eigen::MatrixXd(d.As.transpose() * d.As));
  const Eigen::Index np = free_parameters(train);
  d.train_state = state_of(train, d.A, d.beta, np);
  d.heldout_state = state_of(heldout, d.Ah, d.beta, np);
  return d;
}

AddedColumns add_columns(const NestedDesign& d, const Eigen::MatrixXd& Ctr, const Eigen::MatrixXd& Ch) {
  AddedColumns a;
  a.C = d.rw.asDiagonal() * Ctr;
  const Eigen::Index m = a.C.cols();
  a.cs = a.C.colwise().norm().transpose();
  if (!(a.cs.minCoeff() > 0)) {
    a.absorbed = true;  // not excited by these data
    return a;
  }
  for (Eigen::Index i = 0; i < m; ++i) a.C.col(i) /= a.cs(i);
  const Eigen::MatrixXd AC = d.As.transpose() * a.C;
  a.K = d.empty ? Eigen::MatrixXd(0, m) : Eigen::MatrixXd(d.Gf.solve(AC));
  a.ZZ = a.C.transpose() * a.C - AC.transpose() * a.K;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(a.ZZ);
  if (!(eig.eigenvalues().minCoeff() > 1e-8)) {
    a.absorbed = true;
    return a;
  }
  a.Cr = a.C.transpose() * d.r;
  a.theta_s = a.ZZ.ldlt().solve(a.Cr);
  a.reduction = a.Cr.dot(a.theta_s);
  // Held out: the refit with the columns.
  const Eigen::VectorXd dbeta =
      d.empty ? Eigen::VectorXd() : Eigen::VectorXd((-a.K * a.theta_s).cwiseQuotient(d.scale));
  a.theta = a.theta_s.cwiseQuotient(a.cs);
  a.rh1 =
      d.rh - d.rwh.cwiseProduct(d.empty ? Eigen::VectorXd(Ch * a.theta) : Eigen::VectorXd(d.Ah * dbeta + Ch * a.theta));
  return a;
}

double joint_sse(const DesignStack& heldout, const Eigen::VectorXd& r, int joint) {
  double sse = 0;
  const int n = heldout.joints;
  for (int s = 0; s < heldout.samples(); ++s)
    for (int j = 0; j < n; ++j)
      if (joint == 0 || joint == j + 1)
        sse += r(static_cast<Eigen::Index>(s) * n + j) * r(static_cast<Eigen::Index>(s) * n + j);
  return sse;
}

}  // namespace symoro::diagnose::detail
