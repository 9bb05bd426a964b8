// The all-pose PD audit: scrambled Halton sampling of the box; from the best distinct samples a
// cheap projected-gradient descent finds the basins, and Ipopt minimizes the Rayleigh quotient
// v'M(q)v on |v| = 1 once per basin, to tolerance, with exact first and second derivatives.
#include "symoro/identify/pd_audit.hpp"

#include <IpIpoptApplication.hpp>
#include <IpTNLP.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <mutex>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>

#include "symoro/identify/detail/ipopt_lock.hpp"

namespace symoro::identify {
namespace {

using Clock = std::chrono::steady_clock;
using Eigen::MatrixXd;
using Eigen::VectorXd;

// Starting poses closer than this (normalized distance, see PoseMetric) look into the same
// basin: the next start is taken from elsewhere.
constexpr double kDistinctStart = 0.25;
// Minima closer than this are one minimum reached twice.
constexpr double kSameMinimum = 0.05;
// The descent: steps in box-normalized units, Armijo's sufficient-decrease factor, and at most
// this many trial poses per start.
constexpr double kFirstDescentStep = 0.05, kMaxDescentStep = 0.25, kLastDescentStep = 1e-7;
constexpr double kArmijo = 1e-4;
constexpr int kDescentAttempts = 150;
// Seeds the poses that tell which joints M depends on (fixed: the metric must not depend on
// the audit's seed).
constexpr std::uint64_t kProbeSeed = 12345;
// The grid audit refuses grids larger than this (every pose costs an eigen decomposition).
constexpr double kMaxGridPoses = 5e7;

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("PD audit: " + message);
}

void validate(const InertiaFunction& m, const VectorXd& phi, const AuditDomain& domain) {
  const int n = m.joints();
  require(phi.size() == m.parameters(),
          "phi has " + std::to_string(phi.size()) + " entries, the model " + std::to_string(m.parameters()));
  require(domain.lower.size() == n && domain.upper.size() == n,
          "the domain has " + std::to_string(domain.lower.size()) + " lower and " +
              std::to_string(domain.upper.size()) + " upper bounds, the model " + std::to_string(n) + " joints");
  require(phi.allFinite(), "phi is not finite");
  require(domain.lower.allFinite() && domain.upper.allFinite(), "the domain is not finite");
  for (int j = 0; j < n; ++j)
    require(domain.lower(j) <= domain.upper(j), "joint " + std::to_string(j + 1) + ": lower bound " +
                                                    std::to_string(domain.lower(j)) + " > upper bound " +
                                                    std::to_string(domain.upper(j)));
}

VectorXd clip(const VectorXd& q, const AuditDomain& d) { return q.cwiseMax(d.lower).cwiseMin(d.upper); }

// Ipopt's pose rounded to a grid of 2^-20 rad (1e-6): Ipopt with MUMPS keeps state from one
// solve to the next (its automatic ordering and scaling), so the same local search could end
// 1e-15 apart depending on the searches before it, and a study's SDP vectors then depended on
// which runs its thread had done (test_identify_determinism.cpp). On the grid those endings are
// the same pose except with probability ~1e-9 per coordinate; at a minimum of lambda_min the
// rounding costs O(1e-12) in lambda.
VectorXd snap(const VectorXd& q) {
  constexpr double grid = 1048576.0;  // 2^20
  return (q * grid).array().round().matrix() / grid;
}

// Smallest eigenvalue of a symmetric matrix, reusing the solver's workspace.
class SmallestEigen {
 public:
  explicit SmallestEigen(int n) : solver_(n) {}
  double value(const MatrixXd& M) {
    solver_.compute(M, Eigen::EigenvaluesOnly);
    return solver_.eigenvalues()(0);
  }
  double value(const MatrixXd& M, VectorXd& vector) {
    solver_.compute(M, Eigen::ComputeEigenvectors);
    vector = solver_.eigenvectors().col(0);
    return solver_.eigenvalues()(0);
  }

 private:
  Eigen::SelfAdjointEigenSolver<MatrixXd> solver_;
};

// Halton points whose digits each pass through their own random permutation (one per
// dimension and digit position, from the seed): low discrepancy kept, points decorrelated
// across the high-prime dimensions and different for every seed.
class ScrambledHalton {
 public:
  ScrambledHalton(int dims, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    for (int p = 2; static_cast<int>(bases_.size()) < dims; ++p) {
      bool prime = true;
      for (int b : bases_) prime = prime && p % b != 0;
      if (!prime) continue;
      bases_.push_back(p);
      // Digits down to 2^-32 of the range, far finer than any pose difference that matters.
      const int digits = static_cast<int>(std::ceil(32 / std::log2(p)));
      std::vector<std::vector<int>> perms(digits, std::vector<int>(p));
      for (auto& perm : perms) {
        std::iota(perm.begin(), perm.end(), 0);
        std::shuffle(perm.begin(), perm.end(), rng);
      }
      perms_.push_back(std::move(perms));
    }
  }
  // Point `index` in [0, 1)^dims.
  void point(std::uint64_t index, VectorXd& u) const {
    u.resize(static_cast<Eigen::Index>(bases_.size()));
    for (std::size_t d = 0; d < bases_.size(); ++d) {
      const std::uint64_t b = static_cast<std::uint64_t>(bases_[d]);
      std::uint64_t rest = index;
      double value = 0, weight = 1.0 / static_cast<double>(b);
      for (const auto& perm : perms_[d]) {
        value += weight * perm[rest % b];
        rest /= b;
        weight /= static_cast<double>(b);
      }
      u(static_cast<Eigen::Index>(d)) = value;
    }
  }

 private:
  std::vector<int> bases_;
  std::vector<std::vector<std::vector<int>>> perms_;  // [dimension][digit][digit value]
};

// Distance between poses with every joint scaled to its range, over the joints M depends on
// (joint 1 of a serial arm never enters M: poses differing only there are the same pose).
// A joint counts when dM/dq_k is nonzero at one of a few scattered poses (not at grid-like
// poses: there the derivative of a sin^2 term vanishes).
class PoseMetric {
 public:
  PoseMetric(const InertiaFunction& m, const VectorXd& phi, const AuditDomain& d) {
    const int n = m.joints();
    const ScrambledHalton probes(n, kProbeSeed);
    std::vector<bool> moves(n, false);
    MatrixXd M;
    std::vector<MatrixXd> dM;
    VectorXd u;
    for (int i = 1; i <= 3; ++i) {
      probes.point(static_cast<std::uint64_t>(i), u);
      m.inertia_derivatives(d.lower + u.cwiseProduct(d.upper - d.lower), phi, M, dM);
      for (int k = 0; k < n; ++k) moves[k] = moves[k] || dM[k].cwiseAbs().maxCoeff() > 0;
    }
    scale_ = VectorXd::Zero(n);
    for (int k = 0; k < n; ++k) {
      const double width = d.upper(k) - d.lower(k);
      if (moves[k] && width > 0) scale_(k) = 1 / width;
    }
  }
  double operator()(const VectorXd& a, const VectorXd& b) const { return (a - b).cwiseProduct(scale_).norm(); }

 private:
  VectorXd scale_;
};

// min v'M(q)v  s.t.  v'v = 1,  lower <= q <= upper;  x = (q, v).
class RayleighProblem : public Ipopt::TNLP {
 public:
  RayleighProblem(const InertiaFunction& m, const VectorXd& phi, const AuditDomain& d, VectorXd q0, VectorXd v0,
                  bool exact_hessian)
      : m_(m), phi_(phi), domain_(d), n_(m.joints()), exact_hessian_(exact_hessian), start_(2 * n_) {
    start_ << q0, v0;
  }

  const VectorXd& solution() const { return solution_; }  // empty when Ipopt returned none

  bool get_nlp_info(Ipopt::Index& n, Ipopt::Index& m, Ipopt::Index& nnz_jac_g, Ipopt::Index& nnz_h_lag,
                    IndexStyleEnum& index_style) override {
    n = 2 * n_;
    m = 1;
    nnz_jac_g = n_;
    nnz_h_lag = n * (n + 1) / 2;  // dense lower triangle
    index_style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Ipopt::Index, Ipopt::Number* x_l, Ipopt::Number* x_u, Ipopt::Index, Ipopt::Number* g_l,
                       Ipopt::Number* g_u) override {
    for (int k = 0; k < n_; ++k) {
      x_l[k] = domain_.lower(k);
      x_u[k] = domain_.upper(k);
      x_l[n_ + k] = -kFree;
      x_u[n_ + k] = kFree;
    }
    g_l[0] = g_u[0] = 1;
    return true;
  }

  bool get_starting_point(Ipopt::Index, bool init_x, Ipopt::Number* x, bool init_z, Ipopt::Number*, Ipopt::Number*,
                          Ipopt::Index, bool init_lambda, Ipopt::Number*) override {
    if (!init_x || init_z || init_lambda) return false;
    std::copy(start_.data(), start_.data() + start_.size(), x);
    return true;
  }

  bool eval_f(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Number& f) override {
    if (!evaluate(x, Level::Value)) return false;
    f = v_.dot(M_ * v_);
    return true;
  }

  bool eval_grad_f(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Number* grad) override {
    if (!evaluate(x, Level::First)) return false;
    for (int k = 0; k < n_; ++k) grad[k] = v_.dot(dM_[k] * v_);
    Eigen::Map<VectorXd>(grad + n_, n_) = 2 * M_ * v_;
    return true;
  }

  bool eval_g(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Index, Ipopt::Number* g) override {
    g[0] = Eigen::Map<const VectorXd>(x + n_, n_).squaredNorm();
    return true;
  }

  bool eval_jac_g(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Index, Ipopt::Index, Ipopt::Index* rows,
                  Ipopt::Index* cols, Ipopt::Number* values) override {
    for (int k = 0; k < n_; ++k) {
      if (values == nullptr) {
        rows[k] = 0;
        cols[k] = n_ + k;
      } else {
        values[k] = 2 * x[n_ + k];
      }
    }
    return true;
  }

  bool eval_h(Ipopt::Index, const Ipopt::Number* x, bool, Ipopt::Number sigma, Ipopt::Index,
              const Ipopt::Number* lambda, bool, Ipopt::Index, Ipopt::Index* rows, Ipopt::Index* cols,
              Ipopt::Number* values) override {
    if (!exact_hessian_) return false;
    const int size = 2 * n_;
    if (values == nullptr) {
      int e = 0;
      for (int i = 0; i < size; ++i)
        for (int j = 0; j <= i; ++j, ++e) {
          rows[e] = i;
          cols[e] = j;
        }
      return true;
    }
    if (!evaluate(x, Level::Second)) return false;
    std::vector<VectorXd> dMv(n_);
    for (int k = 0; k < n_; ++k) dMv[k] = dM_[k] * v_;
    int e = 0;
    for (int i = 0; i < size; ++i)
      for (int j = 0; j <= i; ++j, ++e) {
        if (i < n_)  // d2f/dq_i dq_j = v' d2M/dq_i dq_j v
          values[e] = sigma * v_.dot(d2M_[i * n_ + j] * v_);
        else if (j < n_)  // d2f/dv dq_j = 2 dM/dq_j v
          values[e] = sigma * 2 * dMv[j](i - n_);
        else  // d2f/dv2 = 2 M; the constraint v'v adds 2 lambda I
          values[e] = sigma * 2 * M_(i - n_, j - n_) + (i == j ? 2 * lambda[0] : 0.0);
      }
    return true;
  }

  void finalize_solution(Ipopt::SolverReturn, Ipopt::Index n, const Ipopt::Number* x, const Ipopt::Number*,
                         const Ipopt::Number*, Ipopt::Index, const Ipopt::Number*, const Ipopt::Number*, Ipopt::Number,
                         const Ipopt::IpoptData*, Ipopt::IpoptCalculatedQuantities*) override {
    // Whatever the status: the caller keeps the start when this pose is no worse.
    if (x != nullptr) solution_ = Eigen::Map<const VectorXd>(x, n);
  }

 private:
  enum class Level { None, Value, First, Second };
  static constexpr double kFree = 1e20;  // beyond Ipopt's infinity: v is unbounded

  // M and its derivatives at x, computed once per x up to the level asked for.
  bool evaluate(const Ipopt::Number* x, Level level) {
    const Eigen::Map<const VectorXd> xs(x, 2 * n_);
    if (level_ == Level::None || xs != x_) {
      x_ = xs;
      v_ = x_.tail(n_);
      level_ = Level::None;
    }
    if (level_ >= level) return true;
    try {
      const VectorXd q = x_.head(n_);
      if (level == Level::Second) {
        if (!m_.inertia_second_derivatives(q, phi_, M_, dM_, d2M_)) return false;
      } else if (level == Level::First) {
        m_.inertia_derivatives(q, phi_, M_, dM_);
      } else {
        m_.inertia(q, phi_, M_);
      }
    } catch (...) {  // an exception must not unwind through Ipopt
      return false;
    }
    level_ = level;
    return M_.allFinite();
  }

  const InertiaFunction& m_;
  const VectorXd& phi_;
  const AuditDomain& domain_;
  const int n_;
  const bool exact_hessian_;
  VectorXd start_, solution_;

  Level level_ = Level::None;
  VectorXd x_, v_;
  MatrixXd M_;
  std::vector<MatrixXd> dM_, d2M_;
};

// The pose Ipopt reaches from (q0, v0); empty when it returned none.
VectorXd minimize_locally(const InertiaFunction& m, const VectorXd& phi, const AuditDomain& d, const VectorXd& q0,
                          const VectorXd& v0, bool exact_hessian, const AuditOptions& options) {
  auto* problem = new RayleighProblem(m, phi, d, q0, v0, exact_hessian);
  const Ipopt::SmartPtr<Ipopt::TNLP> owner = problem;
  std::lock_guard<std::mutex> lock(detail::ipopt_mutex());  // concurrent audits: one at a time
  // No console journal: Ipopt prints nothing, banner included.
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = new Ipopt::IpoptApplication(false);
  auto& o = *app->Options();
  o.SetIntegerValue("print_level", 0);
  o.SetStringValue("sb", "yes");
  o.SetNumericValue("tol", options.tolerance);
  o.SetIntegerValue("max_iter", options.max_iterations);
  o.SetStringValue("hessian_approximation", exact_hessian ? "exact" : "limited-memory");
  // The start is already near a minimum (see descend): a small barrier parameter and a start
  // left where it is (often on a bound) save most of the iterations.
  o.SetStringValue("mu_strategy", "monotone");
  o.SetNumericValue("mu_init", 1e-9);
  o.SetNumericValue("bound_push", 1e-10);
  o.SetNumericValue("bound_frac", 1e-10);
  if (app->Initialize("") != Ipopt::Solve_Succeeded) return {};  // "": no ipopt.opt from the cwd
  app->OptimizeTNLP(owner);
  if (problem->solution().size() != 2 * m.joints() || !problem->solution().allFinite()) return {};
  return clip(snap(problem->solution().head(m.joints())), d);
}

// Projected steepest descent of lambda_min(q) in joint coordinates scaled to the box (its
// gradient is v' dM/dq v, v the eigenvector of lambda_min): cheap steps that carry a start to
// the bottom of its basin, so that starts sharing a basin are minimized once and Ipopt starts
// close to its minimum. Never worse than the start.
AuditPose descend(const InertiaFunction& m, const VectorXd& phi, const AuditDomain& d, const VectorXd& q0,
                  SmallestEigen& eigen) {
  const int n = m.joints();
  const VectorXd width = d.upper - d.lower;
  VectorXd q = q0, v, g(n), trial;
  MatrixXd M;
  std::vector<MatrixXd> dM;
  m.inertia_derivatives(q, phi, M, dM);
  double lambda = eigen.value(M, v);
  if (std::isnan(lambda)) return {q0, -std::numeric_limits<double>::infinity()};
  double step = kFirstDescentStep;
  int attempts = 0;
  for (; attempts < kDescentAttempts && step > kLastDescentStep; ++attempts) {
    for (int k = 0; k < n; ++k) {
      g(k) = v.dot(dM[k] * v) * width(k);  // d lambda / d(q_k / width_k)
      const bool blocked = (q(k) <= d.lower(k) && g(k) > 0) || (q(k) >= d.upper(k) && g(k) < 0);
      if (width(k) == 0 || blocked) g(k) = 0;
    }
    const double norm = g.norm();
    if (norm == 0) break;
    trial = clip(q - (step / norm) * g.cwiseProduct(width), d);
    double predicted = 0;  // first-order decrease of the projected step
    for (int k = 0; k < n; ++k)
      if (width(k) > 0) predicted += g(k) * (q(k) - trial(k)) / width(k);
    m.inertia(trial, phi, M);
    if (eigen.value(M) < lambda - kArmijo * predicted) {
      q = trial;
      m.inertia_derivatives(q, phi, M, dM);
      lambda = eigen.value(M, v);
      step = std::min(2 * step, kMaxDescentStep);
    } else {
      step /= 2;
    }
  }
  return {q, lambda};
}

// Greedy: walk the poses best first, keep those at least `distance` from every kept one.
std::vector<int> distinct_best(const std::vector<double>& lambda, const std::function<VectorXd(int)>& pose,
                               const PoseMetric& metric, double distance, int count) {
  std::vector<int> order(lambda.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return lambda[a] < lambda[b]; });
  std::vector<int> kept;
  std::vector<VectorXd> kept_poses;
  for (int i : order) {
    if (static_cast<int>(kept.size()) >= count) break;
    const VectorXd q = pose(i);
    bool distinct = true;
    for (const VectorXd& k : kept_poses) distinct = distinct && metric(q, k) >= distance;
    if (!distinct) continue;
    kept.push_back(i);
    kept_poses.push_back(q);
  }
  return kept;
}

void finish(AuditResult& r, std::vector<AuditPose> poses, const PoseMetric& metric, Clock::time_point start) {
  std::sort(poses.begin(), poses.end(),
            [](const AuditPose& a, const AuditPose& b) { return a.lambda_min < b.lambda_min; });
  for (AuditPose& p : poses) {
    bool distinct = true;
    for (const AuditPose& k : r.minima) distinct = distinct && metric(p.q, k.q) >= kSameMinimum;
    if (distinct) r.minima.push_back(std::move(p));
  }
  r.lambda_min = r.minima.front().lambda_min;
  r.worst_pose = r.minima.front().q;
  r.wall = std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

AuditResult audit_pd(const InertiaFunction& m, const VectorXd& phi, const AuditDomain& domain,
                     const AuditOptions& options) {
  const auto start = Clock::now();
  validate(m, phi, domain);
  require(options.samples >= 0 && options.starts >= 0 && options.max_iterations >= 0,
          "samples, starts and max_iterations must not be negative");
  require(options.tolerance > 0, "the tolerance must be positive");
  const int n = m.joints();
  for (const VectorXd& q : options.extra_starts)
    require(q.size() == n && q.allFinite(), "an extra start has " + std::to_string(q.size()) + " entries");

  AuditResult r;
  SmallestEigen eigen(n);
  MatrixXd M;

  // Dense sampling: the box centre, then the scrambled Halton points.
  const int count = options.samples + 1;
  MatrixXd poses(n, count);
  std::vector<double> lambda(count);
  const VectorXd width = domain.upper - domain.lower;
  poses.col(0) = (domain.lower + domain.upper) / 2;
  ScrambledHalton halton(n, options.seed);
  VectorXd u;
  for (int i = 1; i < count; ++i) {
    halton.point(static_cast<std::uint64_t>(i), u);
    poses.col(i) = domain.lower + u.cwiseProduct(width);
  }
  VectorXd q(n);
  for (int i = 0; i < count; ++i) {
    q = poses.col(i);
    m.inertia(q, phi, M);
    lambda[i] = eigen.value(M);
    // A NaN must not hide among the sorted samples: it counts as the worst possible.
    if (std::isnan(lambda[i])) lambda[i] = -std::numeric_limits<double>::infinity();
  }
  r.sampled = count;

  const PoseMetric metric(m, phi, domain);

  // The best distinct samples (at least the best one, which stands when no search improves it).
  const std::vector<int> chosen = distinct_best(
      lambda, [&](int i) { return VectorXd(poses.col(i)); }, metric, kDistinctStart, std::max(options.starts, 1));
  std::vector<AuditPose> found;
  std::vector<VectorXd> starts;
  for (int i : chosen) {
    if (options.starts > 0)
      starts.push_back(poses.col(i));
    else
      found.push_back({poses.col(i), lambda[i]});
  }
  for (const VectorXd& extra : options.extra_starts) starts.push_back(clip(extra, domain));

  if (!starts.empty()) {
    MatrixXd M2;
    std::vector<MatrixXd> dM, d2M;
    const bool exact_hessian = m.inertia_second_derivatives(poses.col(0), phi, M2, dM, d2M);
    // Starts whose descents meet share a basin: Ipopt minimizes each basin once.
    std::vector<AuditPose> descended;
    for (const VectorXd& q0 : starts) descended.push_back(descend(m, phi, domain, q0, eigen));
    std::vector<double> descended_lambda;
    for (const AuditPose& p : descended) descended_lambda.push_back(p.lambda_min);
    const std::vector<int> basins = distinct_best(
        descended_lambda, [&](int i) { return descended[i].q; }, metric, kSameMinimum,
        static_cast<int>(descended.size()));
    for (int i : basins) {
      const VectorXd& q0 = descended[i].q;
      m.inertia(q0, phi, M);
      VectorXd v0;
      eigen.value(M, v0);
      // Both candidates on the grid (see snap): the comparison below then decides between two
      // poses that do not depend on Ipopt's history; with the descent's pose off the grid it
      // could go either way by 1e-12 after different histories.
      AuditPose best{clip(snap(q0), domain), 0};
      m.inertia(best.q, phi, M);
      best.lambda_min = eigen.value(M);
      const VectorXd q1 = minimize_locally(m, phi, domain, q0, v0, exact_hessian, options);
      ++r.local_searches;
      if (q1.size() == n) {
        m.inertia(q1, phi, M);
        const double lambda1 = eigen.value(M);
        if (lambda1 < best.lambda_min) best = {q1, lambda1};
      }
      found.push_back(std::move(best));
    }
  }
  finish(r, std::move(found), metric, start);
  return r;
}

AuditResult grid_audit(const InertiaFunction& m, const VectorXd& phi, const AuditDomain& domain, int points_per_joint) {
  const auto start = Clock::now();
  validate(m, phi, domain);
  require(points_per_joint >= 1, "points_per_joint must be at least 1");
  const int n = m.joints();
  const int p = points_per_joint;
  require(std::pow(static_cast<double>(p), n) <= kMaxGridPoses, "the grid has too many poses");
  long total = 1;
  for (int j = 0; j < n; ++j) total *= p;

  // Pose `index` of the grid: its digits in base p pick each joint's value.
  const auto pose = [&](long index) {
    VectorXd q(n);
    for (int j = 0; j < n; ++j, index /= p) {
      const long i = index % p;
      q(j) = p == 1 ? (domain.lower(j) + domain.upper(j)) / 2
                    : domain.lower(j) + (domain.upper(j) - domain.lower(j)) * static_cast<double>(i) / (p - 1);
    }
    return q;
  };

  AuditResult r;
  SmallestEigen eigen(n);
  MatrixXd M;
  std::vector<double> lambda(static_cast<std::size_t>(total));
  for (long i = 0; i < total; ++i) {
    m.inertia(pose(i), phi, M);
    lambda[i] = eigen.value(M);
    if (std::isnan(lambda[i])) lambda[i] = -std::numeric_limits<double>::infinity();
  }
  r.sampled = static_cast<int>(total);

  const PoseMetric metric(m, phi, domain);
  std::vector<AuditPose> worst;
  for (int i : distinct_best(lambda, pose, metric, kDistinctStart, AuditOptions{}.starts))
    worst.push_back({pose(i), lambda[i]});
  finish(r, std::move(worst), metric, start);
  return r;
}

}  // namespace symoro::identify
