#include "symoro/identify/sdp_projection.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "csdp_problem.hpp"

namespace symoro::identify {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// The distance's metric as a change of variables phi = phi0 + T u with |u| the distance:
// T = diag(1 / w) for weights, T = R^-1 for a metric A = R'R.
struct Metric {
  bool diagonal = true;
  Eigen::VectorXd w;  // diagonal
  Eigen::MatrixXd R;  // full: upper triangular, A = R'R
  Eigen::MatrixXd T;  // full: R^-1

  double distance(const Eigen::VectorXd& d) const {
    return diagonal ? (w.array() * d.array()).matrix().norm() : (R.triangularView<Eigen::Upper>() * d).norm();
  }
  // The coefficient of u_j in M at a pose: sum_i T_ij L_i.
  Eigen::MatrixXd coefficient(const std::vector<Eigen::MatrixXd>& linear, int j) const {
    if (diagonal) return linear[static_cast<std::size_t>(j)] / w(j);
    Eigen::MatrixXd C = Eigen::MatrixXd::Zero(linear[0].rows(), linear[0].cols());
    for (int i = 0; i <= j; ++i)  // T is upper triangular
      if (T(i, j) != 0 && !linear[static_cast<std::size_t>(i)].isZero(0))
        C += T(i, j) * linear[static_cast<std::size_t>(i)];
    return C;
  }
  // phi0 + s T_{:,j} y_j over the free columns.
  Eigen::VectorXd step(const Eigen::VectorXd& phi0, const std::vector<int>& free, const Eigen::VectorXd& y,
                       double s) const {
    Eigen::VectorXd phi = phi0;
    for (std::size_t j = 0; j < free.size(); ++j) {
      const int c = free[j];
      if (diagonal)
        phi(c) += s * y(static_cast<Eigen::Index>(j)) / w(c);
      else
        phi.head(c + 1) += (s * y(static_cast<Eigen::Index>(j))) * T.col(c).head(c + 1);
    }
    return phi;
  }
};

Metric make_metric(const Eigen::VectorXd& weights, const Eigen::MatrixXd& metric, int n, const char* who) {
  Metric m;
  if (metric.size() == 0) {
    m.w = weights.size() == 0 ? Eigen::VectorXd::Ones(n) : weights;
    if (m.w.size() != n)
      throw std::invalid_argument(fmt::format("{}: {} weights for {} parameters", who, weights.size(), n));
    for (int i = 0; i < n; ++i)
      if (!(m.w(i) > 0) || !std::isfinite(m.w(i)))
        throw std::invalid_argument(fmt::format("{}: weight {} must be positive and finite", who, i));
    return m;
  }
  if (weights.size() != 0) throw std::invalid_argument(fmt::format("{}: give weights or a metric, not both", who));
  if (metric.rows() != n || metric.cols() != n || !metric.allFinite())
    throw std::invalid_argument(fmt::format("{}: the metric must be a finite {} x {} matrix, got {} x {}", who, n, n,
                                            metric.rows(), metric.cols()));
  const Eigen::MatrixXd sym = 0.5 * (metric + metric.transpose());
  const Eigen::LLT<Eigen::MatrixXd> llt(sym);
  if (llt.info() != Eigen::Success)
    throw std::invalid_argument(fmt::format("{}: the metric is not positive definite", who));
  m.diagonal = false;
  m.R = llt.matrixU();
  m.T = m.R.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(n, n));
  return m;
}

// M's constant term and parameter coefficients at one pose, and the coefficients of the
// metric's variables u (see Metric).
struct PoseBasis {
  Eigen::MatrixXd constant;
  std::vector<Eigen::MatrixXd> linear, coef;

  Eigen::MatrixXd inertia(const Eigen::VectorXd& phi) const {
    Eigen::MatrixXd M = constant;
    for (std::size_t i = 0; i < linear.size(); ++i)
      if (phi(i) != 0) M += phi(i) * linear[i];
    return M;
  }
};

double lambda_min(const Eigen::MatrixXd& M) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(M, Eigen::EigenvaluesOnly).eigenvalues()(0);
}

// The fixed-pose solution must reach eps within this at every pose (M's units); CSDP's
// feasibility tolerance is relative to the problem's norms, so a miss is solved again with a
// slightly raised target.
constexpr double kPoseTolerance = 1e-10;

struct ScaledSolve {
  Eigen::VectorXd phi;
  detail::LmiSolution lmi;
};

// One CSDP solve of  min |u|^2  s.t.  M(q_k; phi0 + T u) >= target I  over the free columns of
// T, in scaled units: u = s z (z is O(1) when s is the distance) and each pose block divided by
// its size c_k, so that CSDP's relative tolerances mean the same thing whatever the magnitudes
// of the parameters and of M.
ScaledSolve solve_scaled(const std::vector<PoseBasis>& bases, const Eigen::VectorXd& phi0, const Metric& metric,
                         const std::vector<int>& free, double target, double s) {
  const int nf = static_cast<int>(free.size());
  detail::LmiProblem lmi(nf + 1);  // z, then t >= |z|^2

  // Schur block [[I, z], [z', t]] >= 0  <=>  t >= |z|^2.
  Eigen::MatrixXd schur = Eigen::MatrixXd::Zero(nf + 1, nf + 1);
  schur.topLeftCorner(nf, nf).setIdentity();
  const int sb = lmi.add_block(schur);
  for (int j = 0; j <= nf; ++j) {
    Eigen::MatrixXd E = Eigen::MatrixXd::Zero(nf + 1, nf + 1);
    E(j, nf) = E(nf, j) = 1;
    lmi.set_coefficient(sb, j, E);
  }

  for (const PoseBasis& b : bases) {
    const int nq = static_cast<int>(b.constant.rows());
    const Eigen::MatrixXd A = b.inertia(phi0) - target * Eigen::MatrixXd::Identity(nq, nq);
    double c = A.norm();
    for (int j = 0; j < nf; ++j) c = std::max(c, s * b.coef[free[j]].norm());
    if (!(c > 0)) c = 1;
    const int k = lmi.add_block(A / c);
    for (int j = 0; j < nf; ++j) {
      const Eigen::MatrixXd& L = b.coef[free[j]];
      if (L.isZero(0)) continue;
      lmi.set_coefficient(k, j, (s / c) * L);
    }
  }

  Eigen::VectorXd objective = Eigen::VectorXd::Zero(nf + 1);
  objective(nf) = 1;
  lmi.set_objective(objective);

  // CSDP may stall short of the tight default tolerance (codes 4-9): accept a looser solve. The
  // scaling makes the solution's X, Z and y O(1): start there (identity_start), and from CSDP's
  // own start only if that fails.
  ScaledSolve out;
  for (double tolerance : {1e-13, 1e-10, 1e-8}) {
    for (bool identity : {true, false}) {
      detail::LmiSettings settings;
      settings.tolerance = tolerance;
      settings.identity_start = identity;
      out.lmi = lmi.solve(settings);
      if (out.lmi.code <= 3) break;
    }
    if (out.lmi.code <= 3) break;
  }
  out.phi = metric.step(phi0, free, out.lmi.y.head(nf), s);
  return out;
}

// The linearized distance to the margin at the worst violated pose: the step along the gradient
// of lambda_min that would close the violation. A lower-bound-like estimate of the answer's size.
double distance_estimate(const std::vector<PoseBasis>& bases, const Eigen::VectorXd& phi0, const std::vector<int>& free,
                         double target) {
  double est = 0;
  for (const PoseBasis& b : bases) {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(b.inertia(phi0));
    const double violation = target - es.eigenvalues()(0);
    if (violation <= 0) continue;
    const Eigen::VectorXd v = es.eigenvectors().col(0);
    double g2 = 0;
    for (int j : free) g2 += std::pow(v.dot(b.coef[j] * v), 2);
    if (g2 > 0) est = std::max(est, violation / std::sqrt(g2));
  }
  return est;
}

void check_phi(const InertiaFunction& m, const Eigen::VectorXd& phi0, const char* who) {
  if (phi0.size() != m.parameters())
    throw std::invalid_argument(fmt::format("{}: phi0 has {} entries, the model {}", who, phi0.size(), m.parameters()));
  if (!phi0.allFinite()) throw std::invalid_argument(fmt::format("{}: phi0 is not finite", who));
}

ProjectionResult project_on_poses(const InertiaFunction& m, const Eigen::VectorXd& phi0,
                                  const std::vector<Eigen::VectorXd>& poses, double eps, const Metric& metric) {
  const auto t0 = Clock::now();
  const int n = m.parameters();
  if (!std::isfinite(eps)) throw std::invalid_argument("project_on_poses: eps is not finite");

  std::vector<PoseBasis> bases(poses.size());
  for (std::size_t k = 0; k < poses.size(); ++k) {
    if (poses[k].size() != m.joints() || !poses[k].allFinite())
      throw std::invalid_argument(fmt::format("project_on_poses: pose {} is not a finite {}-vector", k, m.joints()));
    m.basis(poses[k], bases[k].constant, bases[k].linear);
    bases[k].coef.resize(static_cast<std::size_t>(n));
    for (int j = 0; j < n; ++j) bases[k].coef[static_cast<std::size_t>(j)] = metric.coefficient(bases[k].linear, j);
  }
  // Variables in no coefficient (diagonal metric: parameters such as viscous friction that no
  // L_i(q_k) holds) do not enter the SDP: they stay at 0.
  std::vector<int> free;
  for (int i = 0; i < n; ++i)
    if (std::any_of(bases.begin(), bases.end(), [&](const PoseBasis& b) { return !b.coef[i].isZero(0); }))
      free.push_back(i);

  ProjectionResult r;
  r.eps = eps;
  r.poses = static_cast<int>(poses.size());
  auto evaluate = [&](const Eigen::VectorXd& phi) {
    r.phi = phi;
    r.lambda_min = std::numeric_limits<double>::infinity();
    r.worst_pose.resize(0);
    for (std::size_t k = 0; k < bases.size(); ++k) {
      const double l = lambda_min(bases[k].inertia(phi));
      if (l < r.lambda_min) {
        r.lambda_min = l;
        r.worst_pose = poses[k];
      }
    }
    r.distance = metric.distance(phi - phi0);
  };

  evaluate(phi0);
  if (bases.empty() || r.lambda_min >= eps) {  // phi0 already satisfies every pose
    r.feasible = true;
    r.status = "ok";
    r.wall = seconds_since(t0);
    return r;
  }
  if (free.empty()) {
    r.status = "no parameter enters M at these poses";
    r.wall = seconds_since(t0);
    return r;
  }

  // Scale from the linearized estimate, refined once the first solution shows the real
  // distance; solving again with a slightly raised target when CSDP's residual leaves a pose
  // just under eps (its feasibility tolerance is relative to the problem's norms).
  double s = distance_estimate(bases, phi0, free, eps);
  if (!(s > 0)) s = std::max(1e-12, 1e-3 * metric.distance(phi0));
  double target = eps;
  ScaledSolve sol;
  for (int attempt = 0; attempt < 6; ++attempt) {
    sol = solve_scaled(bases, phi0, metric, free, target, s);
    ++r.rounds;
    if (!sol.lmi.solved()) {
      evaluate(sol.phi);
      r.status = sol.lmi.message();
      r.wall = seconds_since(t0);
      return r;
    }
    evaluate(sol.phi);
    const double z = r.distance / s;
    const bool well_scaled = z > 0.25 && z < 4;
    const double shortfall = eps - r.lambda_min;
    if (!well_scaled && r.distance > 0) {
      s = r.distance;
      continue;
    }
    if (shortfall > kPoseTolerance) {
      target += 2 * shortfall;
      continue;
    }
    break;
  }
  r.feasible = r.lambda_min >= eps - kPoseTolerance;
  r.status = r.feasible
                 ? sol.lmi.message()
                 : fmt::format("the solution misses the margin by {:.3g} at a working-set pose", eps - r.lambda_min);
  r.wall = seconds_since(t0);
  return r;
}

}  // namespace

ProjectionResult project_on_poses(const InertiaFunction& m, const Eigen::VectorXd& phi0,
                                  const std::vector<Eigen::VectorXd>& poses, double eps, const Eigen::VectorXd& weights,
                                  const Eigen::MatrixXd& metric) {
  check_phi(m, phi0, "project_on_poses");
  return project_on_poses(m, phi0, poses, eps, make_metric(weights, metric, m.parameters(), "project_on_poses"));
}

Eigen::MatrixXd information_metric(const Eigen::MatrixXd& information, double ridge) {
  if (information.rows() != information.cols() || information.rows() == 0 || !information.allFinite())
    throw std::invalid_argument("information_metric: the information matrix must be square, non-empty and finite");
  if (!(ridge >= 0)) throw std::invalid_argument("information_metric: the ridge must be >= 0");
  Eigen::MatrixXd A = 0.5 * (information + information.transpose());
  const double mean_diagonal = A.diagonal().mean();
  if (!(mean_diagonal > 0))
    throw std::invalid_argument("information_metric: the information matrix has no positive diagonal");
  A.diagonal().array() += ridge * mean_diagonal;
  return A;
}

namespace {

// The working set's constraints by their data: poses that differ only in joints M does not
// depend on (the first joint's rotation about gravity, the last joint) are the same constraint,
// and the audit reports them as distinct minima.
class WorkingSet {
 public:
  explicit WorkingSet(const InertiaFunction& m) : m_(m) {}

  // Adds q unless an equivalent pose is already in; returns whether it was added.
  bool add(const Eigen::VectorXd& q) {
    const Eigen::VectorXd sig = signature(q);
    const double tol = 1e-12 * (1 + sig.cwiseAbs().maxCoeff());
    for (const Eigen::VectorXd& s : signatures_)
      if ((s - sig).cwiseAbs().maxCoeff() <= tol) return false;
    signatures_.push_back(sig);
    poses_.push_back(q);
    return true;
  }
  const std::vector<Eigen::VectorXd>& poses() const { return poses_; }
  int size() const { return static_cast<int>(poses_.size()); }

 private:
  Eigen::VectorXd signature(const Eigen::VectorXd& q) const {
    m_.basis(q, constant_, linear_);
    const Eigen::Index s = constant_.size();
    Eigen::VectorXd v(s * static_cast<Eigen::Index>(linear_.size() + 1));
    v.head(s) = constant_.reshaped();
    for (std::size_t i = 0; i < linear_.size(); ++i) v.segment(s * (i + 1), s) = linear_[i].reshaped();
    return v;
  }
  const InertiaFunction& m_;
  std::vector<Eigen::VectorXd> poses_, signatures_;
  mutable Eigen::MatrixXd constant_;
  mutable std::vector<Eigen::MatrixXd> linear_;
};

}  // namespace

ProjectionResult project_pd(const InertiaFunction& m, const Eigen::VectorXd& phi0, const AuditDomain& domain,
                            const ProjectionOptions& options) {
  const auto t0 = Clock::now();
  check_phi(m, phi0, "project_pd");
  const AuditResult a = audit_pd(m, phi0, domain, options.audit);
  ProjectionResult r = project_pd(m, phi0, domain, options, a);
  r.wall = seconds_since(t0);
  return r;
}

ProjectionResult project_pd(const InertiaFunction& m, const Eigen::VectorXd& phi0, const AuditDomain& domain,
                            const ProjectionOptions& options, const AuditResult& phi0_audit) {
  const auto t0 = Clock::now();
  check_phi(m, phi0, "project_pd");
  const Metric metric = make_metric(options.weights, options.metric, m.parameters(), "project_pd");
  if (!(options.eps >= 0) || !std::isfinite(options.eps)) throw std::invalid_argument("project_pd: eps must be >= 0");
  if (domain.joints() != m.joints() || domain.upper.size() != m.joints())
    throw std::invalid_argument("project_pd: the domain does not match the model's joints");
  if (options.poses_per_round < 1 || options.max_rounds < 1)
    throw std::invalid_argument("project_pd: poses_per_round and max_rounds must be >= 1");
  if (!(options.shortfall_raise >= 0) || !std::isfinite(options.shortfall_raise))
    throw std::invalid_argument("project_pd: shortfall_raise must be >= 0");

  // eps = 0 is the rescue: PD strictly (lambda_min > 0), reached through a tiny SDP floor.
  const bool rescue = options.eps == 0;
  const double target = rescue ? options.rescue_floor : options.eps;
  if (rescue && !(options.rescue_floor > 0)) throw std::invalid_argument("project_pd: rescue_floor must be > 0");
  auto accepted = [&](double l) { return rescue ? l > 0 : l >= options.eps - options.accept_slack; };
  auto violates = [&](double l) { return l < target - options.accept_slack; };

  ProjectionResult r;
  r.eps = options.eps;
  r.phi = phi0;
  r.lambda_min = phi0_audit.lambda_min;
  r.worst_pose = phi0_audit.worst_pose;
  auto finish = [&](bool feasible, std::string status) {
    r.feasible = feasible;
    r.status = std::move(status);
    r.distance = metric.distance(r.phi - phi0);
    r.wall = seconds_since(t0);
    return r;
  };
  if (accepted(phi0_audit.lambda_min)) return finish(true, "ok");

  // The working set: the domain's centre and the worst distinct minima of phi0's audit.
  WorkingSet set(m);
  set.add(0.5 * (domain.lower + domain.upper));
  for (const AuditPose& p : phi0_audit.minima) {
    if (set.size() > 2 * options.poses_per_round) break;
    set.add(p.q);
  }

  double raise = 0;  // options.shortfall_raise at work
  // At most the margin itself or 1 % of phi0's violation: raising the margin by d moves phi by
  // about d / |grad lambda_min|, so the raise costs at most ~1 % of the distance.
  const double raise_cap = std::max(target, 0.01 * (target - phi0_audit.lambda_min));
  std::vector<Eigen::VectorXd> seen;
  for (const AuditPose& p : phi0_audit.minima) seen.push_back(p.q);
  for (int round = 1; round <= options.max_rounds; ++round) {
    const ProjectionResult sol = project_on_poses(m, phi0, set.poses(), target + raise, metric);
    r.rounds = round;
    r.poses = set.size();
    r.phi = sol.phi;

    // Every working-set pose starts a descent: the solution sits on the margin there, and the
    // minimizer of each of those basins moves with phi. Plus the last audit's other minima.
    AuditOptions ao = options.audit;
    ao.seed = options.audit.seed + static_cast<std::uint64_t>(round);  // new samples each round
    ao.extra_starts.insert(ao.extra_starts.end(), set.poses().begin(), set.poses().end());
    ao.extra_starts.insert(ao.extra_starts.end(), seen.begin(), seen.end());
    const AuditResult audit = audit_pd(m, sol.phi, domain, ao);
    seen.clear();
    for (const AuditPose& p : audit.minima) seen.push_back(p.q);
    r.lambda_min = audit.lambda_min;
    r.worst_pose = audit.worst_pose;

    if (!sol.feasible)
      return finish(false, fmt::format("round {}: SDP on {} poses: {}", round, set.size(), sol.status));
    if (accepted(audit.lambda_min)) return finish(true, "ok");

    // The raise anticipates the drift of the working set's basin minima, small against the
    // margin. A large shortfall is a basin not yet in the set (the new poses fix it): raising the
    // margin by it put phi far past it (RX-90, 1 s log: lambda_min 10 for eps 0.001, farther than the truth).
    raise = std::min(raise + options.shortfall_raise * std::max(0.0, target + raise - audit.lambda_min), raise_cap);
    int added = 0;
    for (const AuditPose& p : audit.minima) {
      if (added == options.poses_per_round) break;
      if (violates(p.lambda_min) && set.add(p.q)) ++added;
    }
    if (added == 0)
      return finish(false, fmt::format("round {}: lambda_min = {:.3g} at a pose equivalent to a working-set pose",
                                       round, audit.lambda_min));
  }
  return finish(false, fmt::format("not PD-feasible after {} rounds ({} poses): lambda_min = {:.3g}",
                                   options.max_rounds, set.size(), r.lambda_min));
}

ConditionalProjection conditional_projection(const InertiaFunction& m, const Eigen::VectorXd& phi0,
                                             const AuditDomain& domain, const std::vector<double>& margins,
                                             const ProjectionOptions& options) {
  check_phi(m, phi0, "conditional_projection");
  ConditionalProjection c;
  c.audit = audit_pd(m, phi0, domain, options.audit);
  c.phi = phi0;
  if (c.audit.positive_definite()) {
    c.feasible = true;
    return c;
  }
  c.projected = true;
  std::vector<double> ascending = margins;
  std::sort(ascending.begin(), ascending.end());
  for (double eps : ascending) {
    if (!(eps > 0)) throw std::invalid_argument("conditional_projection: margins must be > 0");
    ProjectionOptions o = options;
    o.eps = eps;
    c.attempts.push_back(project_pd(m, phi0, domain, o, c.audit));
    if (c.attempts.back().feasible) {
      c.feasible = true;
      c.eps = eps;
      c.phi = c.attempts.back().phi;
      return c;
    }
  }
  // No margin worked: nothing is handed on (c.phi stays phi0, eps 0); the attempts say how
  // close each came. A vector that failed its audit must not become anyone's starting point.
  return c;
}

}  // namespace symoro::identify
