#include "symoro/identify/physical_consistency.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <fmt/format.h>

#include "csdp_problem.hpp"

namespace symoro::identify {

namespace {

using Clock = std::chrono::steady_clock;
constexpr double kInf = std::numeric_limits<double>::infinity();

// dJ / d(entry) for the slots XX XY XZ YY YZ ZZ MX MY MZ M: J's second-moment block is
// 0.5 tr(I) 1 - I, so a diagonal inertia entry enters all three diagonal entries.
Eigen::Matrix4d unit_pseudo_inertia(int slot) {
  Eigen::Matrix4d E = Eigen::Matrix4d::Zero();
  switch (slot) {
    case 0:
      E.diagonal().head<3>() << -0.5, 0.5, 0.5;
      break;
    case 3:
      E.diagonal().head<3>() << 0.5, -0.5, 0.5;
      break;
    case 5:
      E.diagonal().head<3>() << 0.5, 0.5, -0.5;
      break;
    case 1:
      E(0, 1) = E(1, 0) = -1;
      break;
    case 2:
      E(0, 2) = E(2, 0) = -1;
      break;
    case 4:
      E(1, 2) = E(2, 1) = -1;
      break;
    case 6:
    case 7:
    case 8:
      E(slot - 6, 3) = E(3, slot - 6) = 1;
      break;
    case 9:
      E(3, 3) = 1;
      break;
    default:
      break;
  }
  return E;
}

double lambda_min(const Eigen::Matrix4d& J) {
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(J, Eigen::EigenvaluesOnly).eigenvalues()(0);
}

// Everything the three phases share: B's solution set in the weighted coordinates
// u = W (s - s0), where the prior distance is |u| and, with B~ = B W^-1 = U S V',
//   u = u_p + N z,  u_p = B~^+ (phi - B s0) (orthogonal to B~'s null space N),
// so |W (s - s0)|^2 = |u_p|^2 + |z|^2: the best consistent set is the smallest consistent z.
struct Setup {
  const ConsistencyStructure& st;
  Eigen::VectorXd phi, s0, w, scale, lower, upper;  // scale = 1 / w
  Eigen::MatrixXd Bt;                               // B~
  Eigen::MatrixXd pinv;                             // B~^+
  Eigen::MatrixXd N;                                // ns x nz, orthonormal
  Eigen::VectorXd up, sp;                           // u_p, s_p = s0 + W^-1 u_p
  std::vector<double> size;                         // c_k: each link's ||J|| (its LMI's scale)
  double margin = 0;

  Setup(const ConsistencyStructure& s, const Eigen::VectorXd& phi_, const Eigen::VectorXd& prior,
        const ConsistencyOptions& options)
      : st(s), phi(phi_), s0(prior), margin(options.margin) {
    const Eigen::Index ns = s.B.cols();
    w = options.weights.size() ? options.weights : default_consistency_weights(s, prior, phi_);
    scale = w.cwiseInverse();
    lower = options.lower.size() ? options.lower : Eigen::VectorXd::Constant(ns, -kInf);
    upper = options.upper.size() ? options.upper : Eigen::VectorXd::Constant(ns, kInf);
    if (!options.lower.size())
      for (int k : s.nonnegative) lower(k) = 0;
    Bt = s.B * scale.asDiagonal();

    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Bt, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::VectorXd sv = svd.singularValues();
    const double tol = 1e-12 * (sv.size() ? sv(0) : 0.0) * static_cast<double>(std::max(Bt.rows(), Bt.cols()));
    Eigen::Index r = 0;
    while (r < sv.size() && sv(r) > tol) ++r;
    pinv = svd.matrixV().leftCols(r) * sv.head(r).cwiseInverse().asDiagonal() * svd.matrixU().leftCols(r).transpose();
    N = svd.matrixV().rightCols(ns - r);
    // Rounding noise in rows of parameters that B fixes (FV, IA, ...) would make their bounds
    // look variable: below 1e-14 an entry of an orthonormal basis is such noise.
    N = N.unaryExpr([](double x) { return std::abs(x) < 1e-14 ? 0.0 : x; });
    up = pinv * (phi - s.B * s0);
    sp = standard(up);
    for (const auto& l : s.links)
      size.push_back(std::max({pseudo_inertia(s0, l).norm(), pseudo_inertia(sp, l).norm(), 1e-12}));
  }

  Eigen::VectorXd standard(const Eigen::VectorXd& u) const { return s0 + scale.cwiseProduct(u); }

  // One correction step onto B s = phi (the SVD's rounding, and the cleaned basis).
  Eigen::VectorXd refine(Eigen::VectorXd s) const {
    for (int i = 0; i < 2; ++i) s += scale.cwiseProduct(pinv * (phi - st.B * s));
    return s;
  }
};

// The constraints on s = a + G y (y: the LMI's first G.cols() variables), each divided by its
// size so that CSDP's relative tolerances mean the same thing for every link:
//   (J_k(s) - target_k I) / c_k >= t I,  (s_i - lower_i) / scale_i >= t,  (upper_i - s_i) / scale_i >= t,
// with t the LMI variable t_var (phase 1) or 0 (t_var < 0). A constraint that y does not enter is
// not added: `constant_min` gets its smallest normalized value instead (it is what it is).
struct Constraints {
  double constant_min = kInf;
  std::string constant_what;
};

Constraints add_constraints(detail::LmiProblem& lmi, const Setup& S, const Eigen::VectorXd& a, const Eigen::MatrixXd& G,
                            const std::vector<double>& target, int t_var, double bound_raise = 0) {
  Constraints c;
  const Eigen::Index ny = G.cols();
  auto constant = [&](double v, std::string what) {
    if (v < c.constant_min) {
      c.constant_min = v;
      c.constant_what = std::move(what);
    }
  };
  for (std::size_t k = 0; k < S.st.links.size(); ++k) {
    const auto& l = S.st.links[k];
    const double ck = S.size[k];
    const Eigen::Matrix4d F0 = (pseudo_inertia(a, l) - target[k] * Eigen::Matrix4d::Identity()) / ck;
    std::vector<std::pair<Eigen::Index, Eigen::Matrix4d>> coef;
    for (Eigen::Index j = 0; j < ny; ++j) {
      const Eigen::Matrix4d F = pseudo_inertia(G.col(j), l) / ck;
      if (!F.isZero(0)) coef.emplace_back(j, F);
    }
    if (coef.empty()) {
      constant(lambda_min(F0), fmt::format("link {}'s pseudo-inertia, fixed by the base vector", l.link));
      continue;
    }
    const int b = lmi.add_block(F0);
    for (const auto& [j, F] : coef) lmi.set_coefficient(b, static_cast<int>(j), F);
    if (t_var >= 0) lmi.set_coefficient(b, t_var, -Eigen::Matrix4d::Identity());
  }
  for (Eigen::Index i = 0; i < a.size(); ++i)
    for (int side : {+1, -1}) {
      const double bound = side > 0 ? S.lower(i) : S.upper(i);
      if (!std::isfinite(bound)) continue;
      const double f0 = side * (a(i) - bound) / S.scale(i) - bound_raise;
      if (G.row(i).isZero(0)) {
        constant(f0, fmt::format("{} {} {:.6g}, fixed by the base vector at {:.6g}",
                                 S.st.names[static_cast<std::size_t>(i)], side > 0 ? ">=" : "<=", bound, a(i)));
        continue;
      }
      const int b = lmi.add_block(Eigen::MatrixXd::Constant(1, 1, f0));
      for (Eigen::Index j = 0; j < ny; ++j)
        if (G(i, j) != 0)
          lmi.set_coefficient(b, static_cast<int>(j), Eigen::MatrixXd::Constant(1, 1, side * G(i, j) / S.scale(i)));
      if (t_var >= 0) lmi.set_coefficient(b, t_var, -Eigen::MatrixXd::Ones(1, 1));
    }
  return c;
}

// [[I, v / r], [v' / r, tau]] >= 0 over the LMI variables first..first+n-1 (v) and tau_var
// (tau >= |v|^2 / r^2), or with tau_var < 0 the constant 1 (|v| <= r).
void add_norm_block(detail::LmiProblem& lmi, int first, int n, int tau_var, double r = 1) {
  Eigen::MatrixXd C = Eigen::MatrixXd::Identity(n + 1, n + 1);
  C(n, n) = tau_var < 0 ? 1 : 0;
  const int b = lmi.add_block(C);
  for (int j = 0; j < n; ++j) {
    Eigen::MatrixXd E = Eigen::MatrixXd::Zero(n + 1, n + 1);
    E(j, n) = E(n, j) = 1 / r;
    lmi.set_coefficient(b, first + j, E);
  }
  if (tau_var >= 0) {
    Eigen::MatrixXd E = Eigen::MatrixXd::Zero(n + 1, n + 1);
    E(n, n) = 1;
    lmi.set_coefficient(b, tau_var, E);
  }
}

// CSDP may stall short of the tight tolerance: accept a looser solve, from the identity start
// first (the problems are scaled so that the solution is O(1)) and from CSDP's own start second.
detail::LmiSolution solve(const detail::LmiProblem& lmi, int& solves) {
  detail::LmiSolution out;
  for (double tolerance : {1e-13, 1e-10, 1e-8}) {
    for (bool identity : {true, false}) {
      detail::LmiSettings settings;
      settings.tolerance = tolerance;
      settings.identity_start = identity;
      out = lmi.solve(settings);
      ++solves;
      if (out.solved() || out.code == 1 || out.code == 2) return out;
    }
  }
  return out;
}

// Fills s, lambda_min per link, residual and distance of a result.
void evaluate(const Setup& S, const Eigen::VectorXd& s, const Eigen::VectorXd& phi, ConsistencyResult& r) {
  r.s = s;
  r.link_lambda_min.resize(static_cast<Eigen::Index>(S.st.links.size()));
  r.lambda_min = kInf;
  for (std::size_t k = 0; k < S.st.links.size(); ++k) {
    r.link_lambda_min(static_cast<Eigen::Index>(k)) = lambda_min(pseudo_inertia(s, S.st.links[k]));
    r.lambda_min = std::min(r.lambda_min, r.link_lambda_min(static_cast<Eigen::Index>(k)));
  }
  r.residual = (S.st.B * s - phi).cwiseAbs().maxCoeff();
  r.prior_distance = S.w.cwiseProduct(s - S.s0).norm();
}

// The worst shortfall of s against the targets and bounds, normalized like the LMI; <= 0: met.
double shortfall(const Setup& S, const Eigen::VectorXd& s, const std::vector<double>& target) {
  double worst = -kInf;
  for (std::size_t k = 0; k < S.st.links.size(); ++k)
    worst = std::max(worst, (target[k] - lambda_min(pseudo_inertia(s, S.st.links[k]))) / S.size[k]);
  for (Eigen::Index i = 0; i < s.size(); ++i) {
    if (std::isfinite(S.lower(i))) worst = std::max(worst, (S.lower(i) - s(i)) / S.scale(i));
    if (std::isfinite(S.upper(i))) worst = std::max(worst, (s(i) - S.upper(i)) / S.scale(i));
  }
  return worst;
}

std::vector<double> targets(const Setup& S, double relative) {
  std::vector<double> t;
  for (double c : S.size) t.push_back(S.margin + relative * c);
  return t;
}

// Phase 3: no consistent set maps onto phi. The nearest base vector that has one,
//   min |W_b (B s - phi)|^2 + mu |W (s - s0)|^2  s.t.  s consistent (clearing the margin a little),
// in u = W (s - s0) = sigma v, sigma the size of the prior's gap so that v is O(1).
void nearest_consistent(const Setup& S, const ConsistencyOptions& options, ConsistencyResult& r) {
  const Eigen::Index ns = S.s0.size(), np = S.phi.size();
  // W_b: the full base metric's root when given, else the diagonal weights.
  Eigen::MatrixXd Wb = options.base_metric_root;
  if (!Wb.size()) {
    Eigen::VectorXd wb = options.base_weights;
    if (!wb.size()) {
      wb.resize(np);
      for (Eigen::Index i = 0; i < np; ++i) {
        const double n = S.Bt.row(i).norm();
        wb(i) = n > 0 ? 1 / n : 1;
      }
    }
    Wb = wb.asDiagonal();
  }
  const Eigen::Index nr = Wb.rows();
  const Eigen::MatrixXd A = Wb * S.Bt;  // d(weighted residual) / du
  // The held rows hold exactly: u = u_h + N_h w, u_h the smallest u meeting them, N_h an
  // orthonormal basis of what leaves them unchanged (everything when none are held).
  Eigen::VectorXd uh = Eigen::VectorXd::Zero(ns);
  Eigen::MatrixXd Nh = Eigen::MatrixXd::Identity(ns, ns);
  if (!options.held_rows.empty()) {
    const auto nh = static_cast<Eigen::Index>(options.held_rows.size());
    Eigen::MatrixXd Bh(nh, ns);
    Eigen::VectorXd rh(nh);
    const Eigen::VectorXd Bs0 = S.st.B * S.s0;
    for (Eigen::Index i = 0; i < nh; ++i) {
      const int row = options.held_rows[static_cast<std::size_t>(i)];
      Bh.row(i) = S.Bt.row(row);
      rh(i) = S.phi(row) - Bs0(row);
    }
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Bh, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::VectorXd sv = svd.singularValues();
    const double tol = 1e-12 * (sv.size() ? sv(0) : 0.0) * static_cast<double>(std::max(nh, ns));
    Eigen::Index rank = 0;
    while (rank < sv.size() && sv(rank) > tol) ++rank;
    uh = svd.matrixV().leftCols(rank) * sv.head(rank).cwiseInverse().asDiagonal() *
         svd.matrixU().leftCols(rank).transpose() * rh;
    Nh = svd.matrixV().rightCols(ns - rank);
  }
  const Eigen::VectorXd gap = Wb * (S.st.B * S.s0 - S.phi) + A * uh;
  const double sigma = std::max({gap.norm(), S.up.norm(), 1e-9});
  const Eigen::MatrixXd AN = A * Nh;

  const int nv = static_cast<int>(Nh.cols()), t1 = nv, t2 = nv + 1;
  detail::LmiProblem lmi(nv + 2);
  {  // tau1 >= |gap / sigma + A N_h v|^2
    Eigen::MatrixXd C = Eigen::MatrixXd::Identity(nr + 1, nr + 1);
    C(nr, nr) = 0;
    C.col(nr).head(nr) = gap / sigma;
    C.row(nr).head(nr) = (gap / sigma).transpose();
    const int b = lmi.add_block(C);
    for (int j = 0; j < nv; ++j) {
      Eigen::MatrixXd E = Eigen::MatrixXd::Zero(nr + 1, nr + 1);
      E.col(nr).head(nr) = AN.col(j);
      E.row(nr).head(nr) = AN.col(j).transpose();
      if (!E.isZero(0)) lmi.set_coefficient(b, j, E);
    }
    Eigen::MatrixXd E = Eigen::MatrixXd::Zero(nr + 1, nr + 1);
    E(nr, nr) = 1;
    lmi.set_coefficient(b, t1, E);
  }
  add_norm_block(lmi, 0, nv, t2);  // tau2 >= |v|^2
  const Eigen::MatrixXd G = sigma * S.scale.asDiagonal() * Nh;
  std::vector<double> target = targets(S, options.infeasible_clearance);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(nv + 2);
  b(t1) = 1;
  b(t2) = options.prior_regularization;
  lmi.set_objective(b);
  add_constraints(lmi, S, S.standard(uh), G, target, -1);
  const detail::LmiSolution sol = solve(lmi, r.solves);
  if (!sol.solved()) {
    r.message = fmt::format(
        "no consistent standard set maps onto phi (phase 1: t = {:.3g}); the search for the nearest "
        "base vector that has one failed: {}",
        r.feasibility, sol.message());
    return;
  }
  const Eigen::VectorXd s = S.standard(uh + sigma * Nh * sol.y.head(nv));
  r.phi_consistent = S.st.B * s;
  evaluate(S, s, S.phi, r);
  r.base_distance = (Wb * (r.phi_consistent - S.phi)).norm();
  r.message = fmt::format(
      "no consistent standard set maps onto phi (phase 1: the best smallest-eigenvalue margin is {:.3g} of the "
      "links' size); the nearest base vector that has one is phi_consistent, at distance {:.6g} (max |change| {:.3g}); "
      "phi was not changed",
      r.feasibility, r.base_distance, (r.phi_consistent - S.phi).cwiseAbs().maxCoeff());
}

}  // namespace

const char* to_string(ConsistencyStatus s) {
  switch (s) {
    case ConsistencyStatus::Consistent:
      return "consistent";
    case ConsistencyStatus::NoConsistentSet:
      return "no consistent set";
    case ConsistencyStatus::SolverFailure:
      return "solver failure";
  }
  return "?";
}

Eigen::Matrix4d pseudo_inertia(const Eigen::VectorXd& s, const LinkInertialIndices& link) {
  Eigen::Matrix4d J = Eigen::Matrix4d::Zero();
  for (int slot = 0; slot < 10; ++slot) {
    const int k = link.index[static_cast<std::size_t>(slot)];
    if (k >= 0 && s(k) != 0) J += s(k) * unit_pseudo_inertia(slot);
  }
  return J;
}

Eigen::VectorXd default_consistency_weights(const ConsistencyStructure& st, const Eigen::VectorXd& prior,
                                            const Eigen::VectorXd& phi) {
  const Eigen::Index ns = st.B.cols();
  if (prior.size() != ns || static_cast<Eigen::Index>(st.group.size()) != ns)
    throw std::invalid_argument("default_consistency_weights: the prior or the groups do not match B's columns");
  if (phi.size() && phi.size() != st.B.rows())
    throw std::invalid_argument("default_consistency_weights: phi does not match B's rows");
  constexpr int groups = static_cast<int>(StandardGroup::Other) + 1;
  auto group_rms = [&](const Eigen::VectorXd& v, double* rms) {
    double sum[groups] = {}, count[groups] = {};
    for (Eigen::Index k = 0; k < ns; ++k) {
      const int g = static_cast<int>(st.group[static_cast<std::size_t>(k)]);
      sum[g] += v(k) * v(k);
      count[g] += 1;
    }
    for (int g = 0; g < groups; ++g) rms[g] = count[g] > 0 ? std::sqrt(sum[g] / count[g]) : 0;
  };
  double scale[groups], fallback[groups] = {};
  group_rms(prior, scale);
  if (phi.size() && std::any_of(scale, scale + groups, [](double x) { return x == 0; }))
    group_rms(st.B.completeOrthogonalDecomposition().solve(phi), fallback);
  Eigen::VectorXd w(ns);
  for (Eigen::Index k = 0; k < ns; ++k) {
    const int g = static_cast<int>(st.group[static_cast<std::size_t>(k)]);
    const double rms = scale[g] > 0 ? scale[g] : fallback[g];
    w(k) = rms > 0 ? 1 / rms : 1;
  }
  return w;
}

ConsistencyResult consistent_standard_parameters(const ConsistencyStructure& st, const Eigen::VectorXd& phi,
                                                 const Eigen::VectorXd& prior, const ConsistencyOptions& options) {
  const auto t0 = Clock::now();
  const Eigen::Index np = st.B.rows(), ns = st.B.cols();
  auto require = [](bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(std::string("consistent_standard_parameters: ") + what);
  };
  require(np > 0 && ns > 0 && st.B.allFinite(), "B must be a finite, non-empty matrix");
  require(phi.size() == np && phi.allFinite(), "phi must be finite with one entry per row of B");
  require(prior.size() == ns && prior.allFinite(), "the prior must be finite with one entry per column of B");
  require(st.names.size() == static_cast<std::size_t>(ns) && st.group.size() == static_cast<std::size_t>(ns),
          "names and groups must have one entry per column of B");
  for (const auto& l : st.links)
    for (int k : l.index) require(k >= -1 && k < ns, "a link index is out of range");
  require(!options.weights.size() ||
              (options.weights.size() == ns && (options.weights.array() > 0).all() && options.weights.allFinite()),
          "weights must be positive and finite, one per standard parameter");
  require(!options.lower.size() || options.lower.size() == ns, "lower must have one entry per standard parameter");
  require(!options.upper.size() || options.upper.size() == ns, "upper must have one entry per standard parameter");
  require(
      !options.base_weights.size() || (options.base_weights.size() == np && (options.base_weights.array() > 0).all()),
      "base_weights must be positive, one per base parameter");
  require(
      !options.base_metric_root.size() || (options.base_metric_root.cols() == np &&
                                           options.base_metric_root.allFinite() && options.base_metric_root.rows() > 0),
      "base_metric_root must have one column per base parameter and finite entries");
  for (int row : options.held_rows) require(row >= 0 && row < np, "a held row is out of range");
  require(std::isfinite(options.margin) && options.margin >= 0, "the margin must be >= 0");

  const Setup S(st, phi, prior, options);
  require(!(S.lower.array() > S.upper.array()).any() && !S.lower.hasNaN() && !S.upper.hasNaN(),
          "lower must not exceed upper");
  ConsistencyResult r;
  r.feasibility = std::numeric_limits<double>::quiet_NaN();
  auto finish = [&]() {
    r.wall = std::chrono::duration<double>(Clock::now() - t0).count();
    return r;
  };
  const double phi_tol = 1e-10 * std::max(1.0, phi.cwiseAbs().maxCoeff());
  if ((st.B * S.sp - phi).cwiseAbs().maxCoeff() > phi_tol) {
    evaluate(S, S.refine(S.sp), phi, r);
    r.status = ConsistencyStatus::NoConsistentSet;
    r.message = fmt::format("phi is not in the range of B (no standard vector at all maps onto it: residual {:.3g})",
                            r.residual);
    return finish();
  }

  const int nz = static_cast<int>(S.N.cols());
  const std::vector<double> exact = targets(S, 0);
  // The prior's projection onto B s = phi is the answer when it is consistent (z = 0), to
  // rounding: a prior that already maps onto phi comes back as it is.
  if (shortfall(S, S.sp, exact) <= 1e-13) {
    evaluate(S, S.refine(S.sp), phi, r);
    r.status = ConsistencyStatus::Consistent;
    r.message = "the prior's projection onto B s = phi is consistent";
    return finish();
  }

  // Phase 1: max t s.t. every constraint holds with t to spare, |z| <= R, t <= 1.
  const double R = options.trust_radius * (1 + S.up.norm());
  const Eigen::MatrixXd G = S.scale.asDiagonal() * S.N;  // ds / dz
  double t_star = -kInf;
  Eigen::VectorXd z1 = Eigen::VectorXd::Zero(nz);
  Constraints fixed;
  {
    detail::LmiProblem lmi(nz + 1);
    if (nz > 0) add_norm_block(lmi, 0, nz, -1);  // |y| <= 1, z = R y
    fixed = add_constraints(lmi, S, S.sp, G * R, exact, nz);
    lmi.add_block(Eigen::MatrixXd::Ones(1, 1));
    lmi.set_coefficient(lmi.blocks() - 1, nz, -Eigen::MatrixXd::Ones(1, 1));
    Eigen::VectorXd b = Eigen::VectorXd::Zero(nz + 1);
    b(nz) = -1;
    lmi.set_objective(b);
    const detail::LmiSolution sol = solve(lmi, r.solves);
    if (!sol.solved()) {
      evaluate(S, S.refine(S.sp), phi, r);
      r.status = ConsistencyStatus::SolverFailure;
      r.message = fmt::format("phase 1 (is there a consistent set?) failed: {}", sol.message());
      return finish();
    }
    t_star = sol.y(nz);
    z1 = R * sol.y.head(nz);
  }
  // Constraints the base vector fixes count when they are violated; one met exactly (FS fixed
  // at its bound 0 by a variant, -1.6e-22 after the pseudo-inverse's rounding) would otherwise
  // pin the margin at 0 whatever the links'.
  r.feasibility = fixed.constant_min < -options.feasibility_tolerance ? std::min(t_star, fixed.constant_min) : t_star;
  if (r.feasibility < -options.feasibility_tolerance) {
    r.status = ConsistencyStatus::NoConsistentSet;
    if (fixed.constant_min < -options.feasibility_tolerance) r.feasibility = fixed.constant_min;
    if (options.feasibility_only) {
      evaluate(S, S.refine(S.standard(S.up + S.N * z1)), phi, r);
      r.message = fmt::format(
          "no consistent standard set maps onto phi (phase 1: the best smallest-eigenvalue margin is "
          "{:.3g} of the links' size)",
          r.feasibility);
    } else {
      nearest_consistent(S, options, r);
    }
    if (fixed.constant_min < -options.feasibility_tolerance)
      r.message += fmt::format(" (violated whatever the other parameters: {})", fixed.constant_what);
    return finish();
  }

  if (options.feasibility_only) {
    evaluate(S, S.refine(S.standard(S.up + S.N * z1)), phi, r);
    r.status = ConsistencyStatus::Consistent;
    r.message = fmt::format("consistent (phase 1 margin {:.3g} of the links' size)", r.feasibility);
    return finish();
  }

  // Phase 2: min |z|^2 s.t. consistent, z = sigma y with sigma the distance's size (re-solved when
  // the answer shows another size), and the target raised by CSDP's shortfall when it leaves a
  // link just under it.
  const double lowered = std::min(0.0, t_star);
  // Parameters B fixes are what they are: one a hair under its bound (within the tolerance) stays.
  const double accept = 1e-12 + std::max(0.0, -fixed.constant_min);
  double raise = 0, sigma = std::max(z1.norm(), 1e-9 * (1 + S.up.norm()));
  Eigen::VectorXd s = S.sp;
  std::string last = "not solved";
  bool met = false;
  for (int attempt = 0; attempt < 6 && !met; ++attempt) {
    detail::LmiProblem lmi(nz + 1);
    add_norm_block(lmi, 0, nz, nz);
    const std::vector<double> target = targets(S, lowered + raise);
    add_constraints(lmi, S, S.sp, G * sigma, target, -1, raise);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(nz + 1);
    b(nz) = 1;
    lmi.set_objective(b);
    const detail::LmiSolution sol = solve(lmi, r.solves);
    last = sol.message();
    if (!sol.solved()) break;
    const Eigen::VectorXd z = sigma * sol.y.head(nz);
    s = S.refine(S.standard(S.up + S.N * z));
    const double ratio = z.norm() / sigma;
    if (z.norm() > 0 && (ratio < 0.25 || ratio > 4)) {
      sigma = z.norm();
      continue;
    }
    const double miss = shortfall(S, s, targets(S, lowered));
    if (miss > accept) {
      raise += 2 * miss;
      continue;
    }
    met = true;
  }
  evaluate(S, s, phi, r);
  const double miss = shortfall(S, s, targets(S, lowered));
  if (met && r.residual <= phi_tol) {
    r.status = ConsistencyStatus::Consistent;
    r.message = fmt::format("consistent (phase 1 margin {:.3g} of the links' size); prior distance {:.6g}",
                            r.feasibility, r.prior_distance);
    return finish();
  }
  // Phase 2 can stall where phi sits a hair inside the set's edge (CSDP at the edge of primal
  // feasibility); phase 1's own set is consistent all the same: the answer, said to be not the
  // nearest to the prior.
  ConsistencyResult first = r;
  evaluate(S, S.refine(S.standard(S.up + S.N * z1)), phi, first);
  if (shortfall(S, first.s, targets(S, lowered)) <= accept && first.residual <= phi_tol) {
    r = first;
    r.status = ConsistencyStatus::Consistent;
    r.message = fmt::format(
        "consistent (phase 1 margin {:.3g} of the links' size); phase 1's set, not the nearest to the prior (phase 2 "
        "failed: {}; shortfall {:.3g}); prior distance {:.6g}",
        r.feasibility, last, miss, r.prior_distance);
  } else {
    r.status = ConsistencyStatus::SolverFailure;
    r.message = fmt::format("phase 2 (the set nearest the prior) failed: {}; shortfall {:.3g}, residual {:.3g}", last,
                            miss, r.residual);
  }
  return finish();
}

}  // namespace symoro::identify
