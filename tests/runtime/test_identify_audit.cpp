// The all-pose PD audit and the InertiaFunction it works on, against independent references:
// central differences and the parameter-linear basis for the derivatives, closed-form minima
// on the planar 2R arm, a 200000-pose brute force on CRANE-X7, an independent 3-point grid,
// and a parameter vector built to be PD on that grid but not between its points.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <symoro/crane_x7.hpp>
#include <symoro/planar2r.hpp>

#include "symoro/identify/identification_model.hpp"  // inertia functions from symoro::<robot>_identification
#include "symoro/identify/pd_audit.hpp"
#include "symoro/robot/compiled_model.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/truth.hpp"

namespace {

using Crane = symoro::crane_x7::reduced::Model;
using Planar = symoro::planar2r::Model;
using Eigen::MatrixXd;
using Eigen::VectorXd;
using namespace symoro::identify;

double smallest_eigenvalue(const MatrixXd& M) {
  return Eigen::SelfAdjointEigenSolver<MatrixXd>(M, Eigen::EigenvaluesOnly).eigenvalues()(0);
}

// lambda_min straight from the generated code, bypassing InertiaFunction and the audit.
template <class Model>
double lambda_min_at(const VectorXd& q, const VectorXd& phi) {
  MatrixXd M;
  Model::inertia(q, phi, M);
  return smallest_eigenvalue(M);
}

// The twin's CAD parameters (robots/crane_x7/twin.yaml) as the reduced model's phi.
const VectorXd& crane_phi() {
  static const VectorXd phi = [] {
    const auto config =
        symoro::twin::read_twin_config(std::string(SYMORO_ROBOTS_DIR) + "/crane_x7/twin.yaml", Crane::nq);
    const auto truth = symoro::twin::make_truth(symoro::robot::compiled_model<symoro::crane_x7::Model>(), config);
    return VectorXd(Crane::base_from_standard(truth.standard));
  }();
  return phi;
}

VectorXd uniform(std::mt19937_64& rng, const VectorXd& lower, const VectorXd& upper) {
  std::uniform_real_distribution<double> u(0, 1);
  VectorXd x(lower.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) x(i) = lower(i) + u(rng) * (upper(i) - lower(i));
  return x;
}

VectorXd uniform(std::mt19937_64& rng, int n, double half_width) {
  return uniform(rng, VectorXd::Constant(n, -half_width), VectorXd::Constant(n, half_width));
}

bool inside(const VectorXd& q, const AuditDomain& d) {
  return (q.array() >= d.lower.array()).all() && (q.array() <= d.upper.array()).all();
}

// ---------------------------------------------------------------------------------------------
// InertiaFunction

TEST(InertiaFunction, DerivativesMatchCentralDifferences) {
  const auto f = identification_model<Crane>()->inertia_function();
  constexpr int n = Crane::nq;
  std::mt19937_64 rng(11);
  // CAD values plus noise, so that every term of M is active.
  const VectorXd phi = crane_phi() + uniform(rng, Crane::np, 0.05);
  const double h = 1e-5;
  for (int trial = 0; trial < 5; ++trial) {
    const VectorXd q = uniform(rng, n, M_PI);
    MatrixXd M, M2, value;
    std::vector<MatrixXd> dM, dM2, d2M;
    f->inertia_derivatives(q, phi, M, dM);
    ASSERT_TRUE(f->inertia_second_derivatives(q, phi, M2, dM2, d2M));
    ASSERT_EQ(dM.size(), std::size_t(n));
    ASSERT_EQ(d2M.size(), std::size_t(n * n));
    f->inertia(q, phi, value);
    EXPECT_LE((M - value).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_LE((M2 - value).cwiseAbs().maxCoeff(), 1e-15);

    double scale = 0, scale2 = 0;
    for (int k = 0; k < n; ++k) scale = std::max(scale, dM[k].cwiseAbs().maxCoeff());
    for (const MatrixXd& D : d2M) scale2 = std::max(scale2, D.cwiseAbs().maxCoeff());
    ASSERT_GT(scale, 1e-3);
    ASSERT_GT(scale2, 1e-3);
    for (int k = 0; k < n; ++k) {
      VectorXd plus = q, minus = q;
      plus(k) += h;
      minus(k) -= h;
      // dM/dq_k against differences of the generated double code.
      MatrixXd Mp, Mm;
      Crane::inertia(plus, phi, Mp);
      Crane::inertia(minus, phi, Mm);
      EXPECT_LE((dM[k] - (Mp - Mm) / (2 * h)).cwiseAbs().maxCoeff(), 1e-7 * scale) << "joint " << k + 1;
      EXPECT_LE((dM2[k] - dM[k]).cwiseAbs().maxCoeff(), 1e-14 * scale);
      // d2M/dq_l dq_k against differences of the (already checked) first derivatives.
      std::vector<MatrixXd> dMp, dMm;
      f->inertia_derivatives(plus, phi, Mp, dMp);
      f->inertia_derivatives(minus, phi, Mm, dMm);
      for (int l = 0; l < n; ++l) {
        EXPECT_LE((d2M[l * n + k] - (dMp[l] - dMm[l]) / (2 * h)).cwiseAbs().maxCoeff(), 1e-7 * scale2)
            << "joints " << l + 1 << ", " << k + 1;
        EXPECT_LE((d2M[l * n + k] - d2M[k * n + l]).cwiseAbs().maxCoeff(), 1e-14 * scale2);
      }
    }
    // M never reads joint 1 (vertical first axis) nor joint 8 (the decoupled hand): the audit's
    // pose metric relies on such joints having exactly zero derivatives.
    EXPECT_EQ(dM[0].cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(dM[7].cwiseAbs().maxCoeff(), 0.0);
  }
}

TEST(InertiaFunction, InertiaIsItsParameterLinearBasis) {
  const auto f = identification_model<Crane>()->inertia_function();
  EXPECT_EQ(f->joints(), Crane::nq);
  EXPECT_EQ(f->parameters(), Crane::np);
  std::mt19937_64 rng(12);
  for (int trial = 0; trial < 5; ++trial) {
    const VectorXd q = uniform(rng, Crane::nq, M_PI);
    const VectorXd phi = uniform(rng, Crane::np, 1.0);
    MatrixXd M, C;
    std::vector<MatrixXd> L;
    f->inertia(q, phi, M);
    f->basis(q, C, L);
    ASSERT_EQ(L.size(), std::size_t(Crane::np));
    MatrixXd rebuilt = C;
    for (int i = 0; i < Crane::np; ++i) rebuilt += phi(i) * L[i];
    EXPECT_LE((M - rebuilt).cwiseAbs().maxCoeff(), 1e-12 * M.cwiseAbs().maxCoeff());
    EXPECT_LE((M - M.transpose()).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(C.cwiseAbs().maxCoeff(), 0.0);  // the reduced model's fixed parameters are all 0
  }
}

TEST(InertiaFunction, RejectsWrongSizes) {
  const auto f = identification_model<Crane>()->inertia_function();
  MatrixXd M, C;
  std::vector<MatrixXd> dM, d2M, L;
  const VectorXd q = VectorXd::Zero(Crane::nq), phi = crane_phi();
  EXPECT_THROW(f->inertia(VectorXd::Zero(Crane::nq - 1), phi, M), std::invalid_argument);
  EXPECT_THROW(f->inertia(q, VectorXd::Zero(Crane::np + 1), M), std::invalid_argument);
  EXPECT_THROW(f->inertia_derivatives(q, VectorXd::Zero(3), M, dM), std::invalid_argument);
  EXPECT_THROW(f->inertia_second_derivatives(VectorXd::Zero(2), phi, M, dM, d2M), std::invalid_argument);
  EXPECT_THROW(f->basis(VectorXd::Zero(Crane::nq + 1), C, L), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// The audit on the planar 2R arm: M = [[ZZR1 + ZZ2 + a, ZZ2 + a/2], [ZZ2 + a/2, ZZ2 + IA2]] with
// a = MX2 cos(q2) - MY2 sin(q2) (link length 0.5 folded in by the generator).

VectorXd planar_phi(double zzr1, double zz2, double mx2, double ia2) {
  VectorXd phi = VectorXd::Zero(Planar::np);
  phi(symoro::planar2r::param::ZZR1) = zzr1;
  phi(symoro::planar2r::param::ZZ2) = zz2;
  phi(symoro::planar2r::param::MX2) = mx2;
  phi(symoro::planar2r::param::IA2) = ia2;
  return phi;
}

TEST(PdAudit, PlanarClosedFormMinimumBetweenTheBounds) {
  // ZZ2 = MY2 = 0: M = [[z + a, a/2], [a/2, i]], a = m cos(q2). lambda_min is concave in a (M is
  // affine in a), so over q2 in [-2, 1] it is smallest at an extreme of cos(q2): q2 = 0 (a = m,
  // inside the box) or q2 = -2 (a = m cos 2).
  const double z = 1.0, m = 1.0, ia = 0.2;
  const auto lambda_of_a = [&](double a) {
    return (z + a + ia) / 2 - std::sqrt(std::pow((z + a - ia) / 2, 2) + a * a / 4);
  };
  const double at_zero = lambda_of_a(m), at_lower = lambda_of_a(m * std::cos(-2.0)),
               at_upper = lambda_of_a(m * std::cos(1.0));
  ASSERT_LT(at_zero, at_lower);  // the worst pose is strictly inside
  ASSERT_LT(at_zero, at_upper);

  const auto f = identification_model<Planar>()->inertia_function();
  const VectorXd phi = planar_phi(z, 0, m, ia);
  AuditDomain d;
  d.lower = Eigen::Vector2d(-M_PI, -2.0);
  d.upper = Eigen::Vector2d(M_PI, 1.0);
  const AuditResult r = audit_pd(*f, phi, d);
  EXPECT_NEAR(r.lambda_min, at_zero, 1e-12);
  EXPECT_NEAR(r.worst_pose(1), 0.0, 1e-4);
  EXPECT_TRUE(inside(r.worst_pose, d));
  EXPECT_NEAR(lambda_min_at<Planar>(r.worst_pose, phi), r.lambda_min, 1e-15);

  // The bounds-only grid sees the two ends only.
  const AuditResult bounds = grid_audit(*f, phi, d, 2);
  EXPECT_NEAR(bounds.lambda_min, std::min(at_lower, at_upper), 1e-14);
  EXPECT_EQ(bounds.sampled, 4);
  EXPECT_GT(bounds.lambda_min, r.lambda_min + 0.03);
  // Three points per joint include q2 = -0.5, not 0: still above the true minimum.
  EXPECT_NEAR(grid_audit(*f, phi, d, 3).lambda_min, lambda_of_a(m * std::cos(-0.5)), 1e-14);
}

TEST(PdAudit, PlanarConstantDiagonalInertia) {
  // No first moments and ZZ2 = 0: M = diag(ZZR1, IA2) at every pose, a flat landscape with zero
  // derivatives everywhere; one joint of the box has zero width.
  const auto f = identification_model<Planar>()->inertia_function();
  const VectorXd phi = planar_phi(0.3, 0, 0, 0.2);
  AuditDomain d;
  d.lower = Eigen::Vector2d(-1.0, 0.5);
  d.upper = Eigen::Vector2d(1.0, 0.5);
  const AuditResult r = audit_pd(*f, phi, d);
  EXPECT_NEAR(r.lambda_min, 0.2, 1e-15);
  EXPECT_EQ(r.worst_pose(1), 0.5);
  EXPECT_TRUE(inside(r.worst_pose, d));
  EXPECT_TRUE(r.positive_definite(0.19));
  EXPECT_FALSE(r.positive_definite(0.2));
}

// ---------------------------------------------------------------------------------------------
// The audit on CRANE-X7 (reduced, 8 joints, 39 parameters) over the paper's domain.

TEST(PdAudit, CraneFindsAtLeastTheBruteForceMinimum) {
  const auto f = identification_model<Crane>()->inertia_function();
  const VectorXd& phi = crane_phi();
  const AuditDomain d = audit_domain<Crane>();
  const AuditResult r = audit_pd(*f, phi, d);

  // Independent brute force: 200000 uniform random poses through the generated code.
  std::mt19937_64 rng(2024);
  double brute = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 200000; ++i) brute = std::min(brute, lambda_min_at<Crane>(uniform(rng, d.lower, d.upper), phi));
  std::cout << "[ audit ] lambda_min " << r.lambda_min << " (brute force " << brute << "), " << r.local_searches
            << " local searches, " << r.wall * 1e3 << " ms\n";

  EXPECT_GT(r.lambda_min, 0);  // CAD inertias are physical
  EXPECT_LE(r.lambda_min, brute + 1e-12);
  EXPECT_TRUE(inside(r.worst_pose, d));
  EXPECT_NEAR(lambda_min_at<Crane>(r.worst_pose, phi), r.lambda_min, 1e-15);
  EXPECT_LE(r.lambda_min, grid_audit(*f, phi, d, 3).lambda_min + 1e-12);

  // A local minimum: no joint step of +-1e-4 rad inside the box goes lower.
  for (int j = 0; j < Crane::nq; ++j)
    for (double step : {-1e-4, 1e-4}) {
      VectorXd q = r.worst_pose;
      q(j) = std::clamp(q(j) + step, d.lower(j), d.upper(j));
      EXPECT_GE(lambda_min_at<Crane>(q, phi), r.lambda_min - 1e-12) << "joint " << j + 1 << " step " << step;
    }

  EXPECT_EQ(r.sampled, AuditOptions{}.samples + 1);
  EXPECT_GE(r.local_searches, 1);
  EXPECT_LE(r.local_searches, AuditOptions{}.starts);
  EXPECT_GT(r.wall, 0);
  ASSERT_FALSE(r.minima.empty());
  EXPECT_EQ(r.minima.front().lambda_min, r.lambda_min);
  for (std::size_t i = 0; i < r.minima.size(); ++i) {
    EXPECT_TRUE(inside(r.minima[i].q, d));
    EXPECT_NEAR(lambda_min_at<Crane>(r.minima[i].q, phi), r.minima[i].lambda_min, 1e-15);
    if (i > 0) {
      EXPECT_LE(r.minima[i - 1].lambda_min, r.minima[i].lambda_min);
    }
  }
}

// lambda_min over the 3-points-per-joint grid, enumerated here (independent of grid_audit).
double three_point_grid_lambda(const VectorXd& phi, const AuditDomain& d) {
  constexpr int n = Crane::nq;
  double worst = std::numeric_limits<double>::infinity();
  VectorXd q(n);
  for (int index = 0, total = static_cast<int>(std::pow(3, n)); index < total; ++index) {
    for (int j = 0, rest = index; j < n; ++j, rest /= 3)
      q(j) = d.lower(j) + (d.upper(j) - d.lower(j)) * (rest % 3) / 2.0;
    worst = std::min(worst, lambda_min_at<Crane>(q, phi));
  }
  return worst;
}

// THE case the audit exists for. Raising MX3 (the first moment of link 3 along x3, with no mass
// to back it) couples joints 2-6 through terms in cos and sin of their angles; the 3-point grid
// (every joint at its bounds and centre: -90, 0, 90 deg for most joints) first turns non-PD at
// MX3 = t_grid, but off the grid M is already indefinite at 0.9 t_grid, near q2 = -47 deg.
TEST(PdAudit, CatchesNonPdBetweenTheGridPoints) {
  const auto f = identification_model<Crane>()->inertia_function();
  const AuditDomain d = audit_domain<Crane>();
  const VectorXd& phi0 = crane_phi();
  ASSERT_GT(three_point_grid_lambda(phi0, d), 0);
  const auto with_mx3 = [&](double t) {
    VectorXd phi = phi0;
    phi(symoro::crane_x7::reduced::param::MX3) += t;
    return phi;
  };
  // The grid's own threshold: bracket, then bisect.
  double pd = 0, not_pd = 1e-3;
  while (three_point_grid_lambda(with_mx3(not_pd), d) > 0) {
    pd = not_pd;
    not_pd *= 2;
    ASSERT_LT(not_pd, 10) << "the grid never turns non-PD along MX3";
  }
  for (int i = 0; i < 20; ++i) {
    const double mid = (pd + not_pd) / 2;
    (three_point_grid_lambda(with_mx3(mid), d) > 0 ? pd : not_pd) = mid;
  }
  const VectorXd phi = with_mx3(0.9 * pd);

  const AuditResult grid = grid_audit(*f, phi, d, 3);
  EXPECT_TRUE(grid.positive_definite()) << grid.lambda_min;
  EXPECT_NEAR(grid.lambda_min, three_point_grid_lambda(phi, d), 1e-15);
  EXPECT_EQ(grid.sampled, 6561);

  const AuditResult r = audit_pd(*f, phi, d);
  EXPECT_FALSE(r.positive_definite()) << r.lambda_min;
  EXPECT_LT(r.lambda_min, -1e-4);
  EXPECT_TRUE(inside(r.worst_pose, d));
  // Recomputed independently: M really is indefinite there.
  const double recomputed = lambda_min_at<Crane>(r.worst_pose, phi);
  EXPECT_LT(recomputed, 0);
  EXPECT_NEAR(recomputed, r.lambda_min, 1e-15);
  // The depth of the dip, not just some negative pose: no joint step of +-1e-4 rad goes lower.
  for (int j = 0; j < Crane::nq; ++j)
    for (double step : {-1e-4, 1e-4}) {
      VectorXd q = r.worst_pose;
      q(j) = std::clamp(q(j) + step, d.lower(j), d.upper(j));
      EXPECT_GE(lambda_min_at<Crane>(q, phi), r.lambda_min - 1e-12) << "joint " << j + 1 << " step " << step;
    }

  // Off the grid: some joint that M depends on (2-7) is far from its three grid values, and the
  // nearest grid pose is PD.
  double off = 0;
  VectorXd nearest = r.worst_pose;
  for (int j = 0; j < Crane::nq; ++j) {
    double best = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      const double g = d.lower(j) + (d.upper(j) - d.lower(j)) * k / 2.0;
      if (std::abs(r.worst_pose(j) - g) < best) {
        best = std::abs(r.worst_pose(j) - g);
        nearest(j) = g;
      }
    }
    if (j >= 1 && j <= 6) off = std::max(off, best);
  }
  EXPECT_GT(off, 0.1) << r.worst_pose.transpose();
  EXPECT_GT(lambda_min_at<Crane>(nearest, phi), 0);
}

// ---------------------------------------------------------------------------------------------
// Options, Hessian fallback, threads, errors.

// The same model without second derivatives: the audit falls back on a limited-memory Hessian.
class FirstOrderOnly final : public InertiaFunction {
 public:
  explicit FirstOrderOnly(const InertiaFunction& m) : m_(m) {}
  int joints() const override { return m_.joints(); }
  int parameters() const override { return m_.parameters(); }
  void inertia(const VectorXd& q, const VectorXd& phi, MatrixXd& M) const override { m_.inertia(q, phi, M); }
  void basis(const VectorXd& q, MatrixXd& C, std::vector<MatrixXd>& L) const override { m_.basis(q, C, L); }
  void inertia_derivatives(const VectorXd& q, const VectorXd& phi, MatrixXd& M,
                           std::vector<MatrixXd>& dM) const override {
    m_.inertia_derivatives(q, phi, M, dM);
  }

 private:
  const InertiaFunction& m_;
};

TEST(PdAudit, LimitedMemoryHessianFindsTheSameMinimum) {
  const auto f = identification_model<Crane>()->inertia_function();
  const FirstOrderOnly first(*f);
  const AuditDomain d = audit_domain<Crane>();
  const VectorXd& phi = crane_phi();
  const AuditResult exact = audit_pd(*f, phi, d);
  const AuditResult approximate = audit_pd(first, phi, d);
  EXPECT_NEAR(approximate.lambda_min, exact.lambda_min, 1e-10);
  EXPECT_NEAR(lambda_min_at<Crane>(approximate.worst_pose, phi), approximate.lambda_min, 1e-15);
}

TEST(PdAudit, ExtraStartsAndNoSearch) {
  const auto f = identification_model<Crane>()->inertia_function();
  const AuditDomain d = audit_domain<Crane>();
  const VectorXd& phi = crane_phi();
  const AuditResult full = audit_pd(*f, phi, d);

  // Sampling only: the best sample, never below the minimized result.
  AuditOptions sampling;
  sampling.starts = 0;
  const AuditResult sampled = audit_pd(*f, phi, d, sampling);
  EXPECT_EQ(sampled.local_searches, 0);
  ASSERT_EQ(sampled.minima.size(), 1u);
  EXPECT_GE(sampled.lambda_min, full.lambda_min);
  EXPECT_NEAR(lambda_min_at<Crane>(sampled.worst_pose, phi), sampled.lambda_min, 1e-15);

  // One extra start near the worst pose and nothing else: it descends back to it.
  AuditOptions extra;
  extra.samples = 0;
  extra.starts = 0;
  VectorXd near = full.worst_pose;
  near(2) += 0.05;
  near(5) -= 0.05;
  extra.extra_starts = {near};
  const AuditResult again = audit_pd(*f, phi, d, extra);
  EXPECT_EQ(again.sampled, 1);
  EXPECT_EQ(again.local_searches, 1);
  EXPECT_NEAR(again.lambda_min, full.lambda_min, 1e-12);
  EXPECT_LT(again.lambda_min, lambda_min_at<Crane>(near, phi));
}

TEST(PdAudit, SilentAndSafeFromSeveralThreads) {
  const auto f = identification_model<Crane>()->inertia_function();
  const AuditDomain d = audit_domain<Crane>();
  const VectorXd& phi = crane_phi();
  testing::internal::CaptureStdout();
  testing::internal::CaptureStderr();
  const AuditResult serial = audit_pd(*f, phi, d);
  std::vector<AuditResult> results(4);
  std::vector<std::thread> threads;
  for (auto& result : results) threads.emplace_back([&] { result = audit_pd(*f, phi, d); });
  for (auto& t : threads) t.join();
  const std::string out = testing::internal::GetCapturedStdout();
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(out, "");
  EXPECT_EQ(err, "");
  for (const AuditResult& r : results) {
    EXPECT_DOUBLE_EQ(r.lambda_min, serial.lambda_min);
    EXPECT_LE((r.worst_pose - serial.worst_pose).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(PdAudit, RejectsBadInput) {
  const auto f = identification_model<Crane>()->inertia_function();
  const AuditDomain d = audit_domain<Crane>();
  const VectorXd& phi = crane_phi();
  EXPECT_THROW(audit_pd(*f, VectorXd::Zero(Crane::np - 1), d), std::invalid_argument);
  EXPECT_THROW(grid_audit(*f, VectorXd::Zero(Crane::np + 1), d, 3), std::invalid_argument);
  AuditDomain short_domain{d.lower.head(7), d.upper.head(7)};
  EXPECT_THROW(audit_pd(*f, phi, short_domain), std::invalid_argument);
  AuditDomain reversed = d;
  std::swap(reversed.lower(3), reversed.upper(3));
  EXPECT_THROW(audit_pd(*f, phi, reversed), std::invalid_argument);
  EXPECT_THROW(grid_audit(*f, phi, reversed, 3), std::invalid_argument);
  EXPECT_THROW(grid_audit(*f, phi, d, 0), std::invalid_argument);
  AuditOptions bad_start;
  bad_start.extra_starts = {VectorXd::Zero(3)};
  EXPECT_THROW(audit_pd(*f, phi, d, bad_start), std::invalid_argument);
  AuditOptions negative;
  negative.samples = -1;
  EXPECT_THROW(audit_pd(*f, phi, d, negative), std::invalid_argument);
}

}  // namespace
