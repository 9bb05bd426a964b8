// The PD-feasible SDP projection (paper eqs. sdp_projection, sdp_rescue): the CSDP solve on fixed
// poses against closed-form projections (clipping, eigenvalue clipping in the Frobenius norm,
// the weighted projection onto a half-space), against its optimality conditions on CRANE-X7,
// and the exchange loop and conditional step against the all-pose audit.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <thread>
#include <type_traits>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <gtest/gtest.h>

#include <symoro/crane_x7.hpp>
#include <symoro/rx90.hpp>

#include "symoro/identify/identification_model.hpp"  // inertia functions from symoro::<robot>_identification
#include "symoro/identify/sdp_projection.hpp"
#include "symoro/robot/compiled_model.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/truth.hpp"
#include "affine_inertia.hpp"
#include "test_support.hpp"

namespace {

using namespace symoro::identify;
using symoro::test::AffineInertia;
using symoro::test::clip_eigenvalues;
using symoro::test::frobenius_model;
using symoro::test::frobenius_params;
using symoro::test::unit;

const std::vector<Eigen::VectorXd> kOnePose{Eigen::VectorXd::Zero(1)};

std::vector<Eigen::VectorXd> one_pose(int joints) { return {Eigen::VectorXd::Zero(joints)}; }

TEST(SdpProjection, DiagonalConstraintClipsAndLeavesOtherParametersAlone) {
  // M = diag(phi_0, phi_1, phi_2); phi_3 (a "friction" parameter) does not enter M.
  const int n = 3;
  std::vector<Eigen::MatrixXd> L{unit(n, 0, 0), unit(n, 1, 1), unit(n, 2, 2), Eigen::MatrixXd::Zero(n, n)};
  const AffineInertia m(Eigen::MatrixXd::Zero(n, n), L);
  Eigen::VectorXd phi0(4);
  phi0 << 0.5, -0.2, 0.003, 7.25;
  const double eps = 0.01;
  const ProjectionResult r = project_on_poses(m, phi0, one_pose(n), eps);
  ASSERT_TRUE(r.feasible) << r.status;
  EXPECT_NEAR(r.phi(0), 0.5, 1e-8);
  EXPECT_NEAR(r.phi(1), eps, 1e-8);
  EXPECT_NEAR(r.phi(2), eps, 1e-8);
  EXPECT_EQ(r.phi(3), 7.25);  // exactly
  EXPECT_NEAR(r.distance, std::hypot(0.21, 0.007), 1e-8);
  EXPECT_GE(r.lambda_min, eps - 1e-10);

  // Separable: the weights do not move the clipping, but they scale the distance.
  Eigen::VectorXd w(4);
  w << 3, 0.5, 20, 1;
  const ProjectionResult rw = project_on_poses(m, phi0, one_pose(n), eps, w);
  ASSERT_TRUE(rw.feasible) << rw.status;
  EXPECT_NEAR(rw.phi(1), eps, 1e-8);
  EXPECT_NEAR(rw.phi(2), eps, 1e-8);
  EXPECT_NEAR(rw.distance, std::hypot(0.5 * 0.21, 20 * 0.007), 1e-8);
}

TEST(SdpProjection, FrobeniusProjectionIsEigenvalueClipping) {
  // One negative eigen-direction: a rank-one correction; two: rank two.
  const int n = 3;
  const AffineInertia m = frobenius_model(n);
  Eigen::MatrixXd Q = Eigen::MatrixXd::Random(n, n);
  Q = Eigen::HouseholderQR<Eigen::MatrixXd>(Q).householderQ();
  for (const Eigen::Vector3d& l : {Eigen::Vector3d(-0.3, 0.02, 0.7), Eigen::Vector3d(-0.05, -0.4, 1.2)}) {
    const Eigen::MatrixXd M0 = Q * l.asDiagonal() * Q.transpose();
    const double eps = 0.005;
    const ProjectionResult r = project_on_poses(m, frobenius_params(M0), one_pose(n), eps);
    ASSERT_TRUE(r.feasible) << r.status;
    const Eigen::MatrixXd expected = clip_eigenvalues(M0, eps);
    EXPECT_LT((r.phi - frobenius_params(expected)).norm(), 1e-7) << r.phi.transpose();
    EXPECT_NEAR(r.distance, (expected - M0).norm(), 1e-8);
    EXPECT_NEAR(r.lambda_min, eps, 1e-8);
  }
}

TEST(SdpProjection, ScaledDownProblemKeepsItsAccuracy) {
  // The same clipping with M ~ 1e-4 and eps = 1e-6: the scaling makes CSDP's relative
  // tolerances mean the same thing at any magnitude.
  const int n = 3;
  const AffineInertia m = frobenius_model(n);
  Eigen::MatrixXd Q = Eigen::MatrixXd::Random(n, n);
  Q = Eigen::HouseholderQR<Eigen::MatrixXd>(Q).householderQ();
  const Eigen::MatrixXd M0 = Q * Eigen::Vector3d(-2e-5, 3e-4, 1e-4).asDiagonal() * Q.transpose();
  const double eps = 1e-6;
  const ProjectionResult r = project_on_poses(m, frobenius_params(M0), one_pose(n), eps);
  ASSERT_TRUE(r.feasible) << r.status;
  const Eigen::MatrixXd expected = clip_eigenvalues(M0, eps);
  EXPECT_LT((r.phi - frobenius_params(expected)).norm(), 1e-7 * 2.1e-5);
  EXPECT_NEAR(r.distance, 2.1e-5, 1e-7 * 2.1e-5);
}

TEST(SdpProjection, WeightedHalfSpaceProjection) {
  // 1 x 1 M = 0.1 + phi_0 - 2 phi_1 >= eps: the W-weighted projection onto a half-space,
  // d = delta W^-2 a / (a' W^-2 a) with a = (1, -2).
  const AffineInertia m(Eigen::MatrixXd::Constant(1, 1, 0.1),
                        {Eigen::MatrixXd::Constant(1, 1, 1.0), Eigen::MatrixXd::Constant(1, 1, -2.0)});
  Eigen::VectorXd phi0(2), w(2), a(2);
  phi0 << -0.3, 0.05;
  w << 2, 0.25;
  a << 1, -2;
  const double eps = 0.002;
  const double delta = eps - (0.1 + a.dot(phi0));
  const Eigen::VectorXd winv2 = w.cwiseProduct(w).cwiseInverse();
  const Eigen::VectorXd d = delta * winv2.cwiseProduct(a) / a.dot(winv2.cwiseProduct(a));
  const ProjectionResult r = project_on_poses(m, phi0, kOnePose, eps, w);
  ASSERT_TRUE(r.feasible) << r.status;
  EXPECT_LT((r.phi - phi0 - d).norm(), 1e-8) << (r.phi - phi0).transpose() << " vs " << d.transpose();
  EXPECT_NEAR(r.distance, w.cwiseProduct(d).norm(), 1e-8);
}

TEST(SdpProjection, AlreadyFeasibleIsReturnedUnchanged) {
  const AffineInertia m = frobenius_model(2);
  const Eigen::VectorXd phi0 = frobenius_params(Eigen::Matrix2d{{0.3, 0.1}, {0.1, 0.2}});
  const ProjectionResult r = project_on_poses(m, phi0, one_pose(2), 0.01);
  EXPECT_TRUE(r.feasible);
  EXPECT_EQ(r.phi, phi0);
  EXPECT_EQ(r.distance, 0);
  EXPECT_EQ(r.rounds, 0);
}

TEST(SdpProjection, InfeasibleConstraintsAreReported) {
  // M = diag(-1, phi_0): no phi makes it PD.
  const AffineInertia m(Eigen::Vector2d(-1, 0).asDiagonal().toDenseMatrix(), {unit(2, 1, 1)});
  const ProjectionResult r = project_on_poses(m, Eigen::VectorXd::Constant(1, -0.5), one_pose(2), 0.01);
  EXPECT_FALSE(r.feasible);
  EXPECT_FALSE(r.status.empty());
  EXPECT_NE(r.status, "ok");
}

TEST(SdpProjection, PrintsNothingAndIsSafeFromSeveralThreads) {
  const int n = 4;
  const AffineInertia m = frobenius_model(n);
  Eigen::MatrixXd Q = Eigen::MatrixXd::Random(n, n);
  Q = Eigen::HouseholderQR<Eigen::MatrixXd>(Q).householderQ();
  const Eigen::MatrixXd M0 = Q * Eigen::Vector4d(-0.3, 0.02, -0.1, 0.7).asDiagonal() * Q.transpose();
  const Eigen::VectorXd expected = frobenius_params(clip_eigenvalues(M0, 0.01));

  // CSDP's easy_sdp() would read param.csdp from the working directory (printlevel included):
  // one asking for CSDP's most verbose output must change nothing.
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "symoro_test_identify_sdp";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "param.csdp") << "printlevel=5\naxtol=1e-2\natytol=1e-2\nobjtol=1e-2\n";
  const std::filesystem::path cwd = std::filesystem::current_path();
  std::filesystem::current_path(dir);
  testing::internal::CaptureStdout();
  const ProjectionResult r = project_on_poses(m, frobenius_params(M0), one_pose(n), 0.01);
  const std::string printed = testing::internal::GetCapturedStdout();
  std::filesystem::current_path(cwd);
  std::filesystem::remove_all(dir);
  EXPECT_EQ(printed, "");
  ASSERT_TRUE(r.feasible) << r.status;
  EXPECT_LT((r.phi - expected).norm(), 1e-7);

  std::vector<ProjectionResult> out(8);
  std::vector<std::thread> threads;
  for (auto& o : out)
    threads.emplace_back([&, p = &o] {
      for (int rep = 0; rep < 5; ++rep) *p = project_on_poses(m, frobenius_params(M0), one_pose(n), 0.01);
    });
  for (auto& t : threads) t.join();
  for (const auto& o : out) {
    ASSERT_TRUE(o.feasible) << o.status;
    EXPECT_LT((o.phi - expected).norm(), 1e-7);
    EXPECT_EQ(o.phi, r.phi);  // the same deterministic computation
  }
}

// ---- CRANE-X7 (the paper's reduced 39-parameter model) ----

using Reduced = symoro::crane_x7::reduced::Model;
namespace param = symoro::crane_x7::reduced::param;

double smallest_eigenvalue(const Eigen::MatrixXd& M) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(M, Eigen::EigenvaluesOnly).eigenvalues()(0);
}

// The CAD truth in the reduced base parameters: PD over the audit box (lambda_min ~ 0.004).
Eigen::VectorXd truth_phi() {
  const auto config = symoro::twin::read_twin_config(SYMORO_ROBOTS_DIR "/crane_x7/twin.yaml", Reduced::nq);
  const auto truth = symoro::twin::make_truth(symoro::robot::compiled_model<symoro::crane_x7::Model>(), config);
  return Reduced::base_from_standard(truth.standard);
}

// The truth with a few inertia parameters pushed negative, like a rough OLS estimate: not PD.
Eigen::VectorXd non_pd_phi() {
  Eigen::VectorXd phi = truth_phi();
  phi(param::ZZR1) = -0.5 * std::abs(phi(param::ZZR1));
  phi(param::ZZR3) = -0.5 * std::abs(phi(param::ZZR3));
  phi(param::IA5) = -0.5 * std::abs(phi(param::IA5));
  phi(param::IA7) = -0.8 * std::abs(phi(param::IA7));
  return phi;
}

bool is_friction(int i) { return std::string(Reduced::parameters[i].family) == "FV"; }

double lambda_min_at(const InertiaFunction& m, const Eigen::VectorXd& phi, const Eigen::VectorXd& q) {
  Eigen::MatrixXd M;
  m.inertia(q, phi, M);  // the generated inertia(), not the basis the SDP was built from
  return smallest_eigenvalue(M);
}

double lambda_min_over(const InertiaFunction& m, const Eigen::VectorXd& phi,
                       const std::vector<Eigen::VectorXd>& poses) {
  double l = std::numeric_limits<double>::infinity();
  for (const auto& q : poses) l = std::min(l, lambda_min_at(m, phi, q));
  return l;
}

std::vector<Eigen::VectorXd> random_poses(const AuditDomain& d, int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Eigen::VectorXd> poses{0.5 * (d.lower + d.upper)};
  for (int k = 1; k < count; ++k) {
    Eigen::VectorXd q(d.joints());
    for (int j = 0; j < d.joints(); ++j) q(j) = d.lower(j) + u(rng) * (d.upper(j) - d.lower(j));
    poses.push_back(q);
  }
  return poses;
}

// An independent solver of the same fixed-pose problem: log-barrier Newton iterations on
//   |phi - phi0|^2 - mu sum_k log det(M(q_k; phi) - eps I),  mu -> 0,
// from a strictly feasible start, with the exact gradient and Hessian of the barrier.
Eigen::VectorXd barrier_projection(const InertiaFunction& m, const std::vector<Eigen::VectorXd>& poses,
                                   const Eigen::VectorXd& phi0, double eps, Eigen::VectorXd x) {
  const int n = m.parameters();
  std::vector<Eigen::MatrixXd> C(poses.size());
  std::vector<std::vector<Eigen::MatrixXd>> L(poses.size());
  for (std::size_t k = 0; k < poses.size(); ++k) m.basis(poses[k], C[k], L[k]);
  const int nq = m.joints();
  auto slack = [&](const Eigen::VectorXd& phi, std::size_t k) {
    Eigen::MatrixXd G = C[k] - eps * Eigen::MatrixXd::Identity(nq, nq);
    for (int i = 0; i < n; ++i) G += phi(i) * L[k][i];
    return G;
  };
  auto merit = [&](const Eigen::VectorXd& phi, double mu, double& f) {
    f = (phi - phi0).squaredNorm();
    for (std::size_t k = 0; k < poses.size(); ++k) {
      Eigen::LLT<Eigen::MatrixXd> llt(slack(phi, k));
      if (llt.info() != Eigen::Success || llt.matrixL().toDenseMatrix().diagonal().minCoeff() <= 0) return false;
      f -= 2 * mu * llt.matrixL().toDenseMatrix().diagonal().array().log().sum();
    }
    return true;
  };
  for (double mu = 1e-4; mu > 1e-17; mu *= 0.2) {
    for (int it = 0; it < 100; ++it) {
      Eigen::VectorXd g = 2 * (x - phi0);
      Eigen::MatrixXd H = 2 * Eigen::MatrixXd::Identity(n, n);
      for (std::size_t k = 0; k < poses.size(); ++k) {
        const Eigen::MatrixXd Ginv = slack(x, k).inverse();
        std::vector<Eigen::MatrixXd> A(n);
        for (int i = 0; i < n; ++i) {
          A[i] = Ginv * L[k][i];
          g(i) -= mu * A[i].trace();
        }
        for (int i = 0; i < n; ++i)
          for (int j = i; j < n; ++j)
            H(i, j) = H(j, i) = H(i, j) + mu * (A[i].array() * A[j].transpose().array()).sum();
      }
      const Eigen::VectorXd dx = -H.ldlt().solve(g);
      const double decrement = -g.dot(dx);
      if (decrement < 1e-30) break;
      double f0, f1, t = 1;
      merit(x, mu, f0);
      while (t > 1e-20 && (!merit(x + t * dx, mu, f1) || f1 > f0 - 0.25 * t * decrement)) t *= 0.5;
      x += t * dx;
      if (decrement < 1e-28) break;
    }
  }
  return x;
}

class CraneX7Projection : public testing::Test {
 protected:
  std::unique_ptr<InertiaFunction> m = identification_model<Reduced>()->inertia_function();
  AuditDomain domain = audit_domain<Reduced>();
  Eigen::VectorXd truth = truth_phi();
  Eigen::VectorXd phi0 = non_pd_phi();
};

TEST_F(CraneX7Projection, FixedPoseSolutionIsFeasibleAndOptimal) {
  const double eps = 0.002;
  const std::vector<Eigen::VectorXd> poses = random_poses(domain, 24, 7);
  ASSERT_LT(lambda_min_over(*m, phi0, poses), 0);
  ASSERT_GT(lambda_min_over(*m, truth, poses), eps);  // the truth: a trivially feasible point

  const ProjectionResult r = project_on_poses(*m, phi0, poses, eps);
  ASSERT_TRUE(r.feasible) << r.status;
  EXPECT_EQ(r.poses, 24);
  for (const auto& q : poses) EXPECT_GE(lambda_min_at(*m, r.phi, q), eps - 1e-8);
  for (int i = 0; i < Reduced::np; ++i)
    if (is_friction(i)) EXPECT_EQ(r.phi(i), phi0(i)) << Reduced::parameters[i].name;
  EXPECT_NEAR(r.distance, (r.phi - phi0).norm(), 1e-15);
  EXPECT_LT(r.distance, (truth - phi0).norm());

  // Optimality: a step from the solution toward phi0 leaves the feasible set at once...
  const Eigen::VectorXd back = r.phi + 1e-3 * (phi0 - r.phi);
  EXPECT_LT(lambda_min_over(*m, back, poses), eps - 1e-7);
  // ...and the independent barrier solver, started from the truth, reaches the same point.
  const Eigen::VectorXd ref = barrier_projection(*m, poses, phi0, eps, truth);
  EXPECT_GE(lambda_min_over(*m, ref, poses), eps - 1e-12);
  EXPECT_LT((r.phi - ref).norm(), 1e-8 * r.distance) << "distance " << r.distance << " vs " << (ref - phi0).norm();
  EXPECT_LE(r.distance, (ref - phi0).norm() + 1e-9 * r.distance);

  // With weights the answer moves, still feasible and no farther (in that norm) than the truth.
  Eigen::VectorXd w = Eigen::VectorXd::Ones(Reduced::np);
  w(param::ZZR1) = 10;
  const ProjectionResult rw = project_on_poses(*m, phi0, poses, eps, w);
  ASSERT_TRUE(rw.feasible) << rw.status;
  EXPECT_GE(lambda_min_over(*m, rw.phi, poses), eps - 1e-8);
  EXPECT_NEAR(rw.distance, w.cwiseProduct(rw.phi - phi0).norm(), 1e-15);
  EXPECT_LT(rw.distance, w.cwiseProduct(truth - phi0).norm());
  EXPECT_LT(std::abs(rw.phi(param::ZZR1) - phi0(param::ZZR1)), std::abs(r.phi(param::ZZR1) - phi0(param::ZZR1)));
}

// A fresh audit, denser and with another seed than the ones project_pd ran.
AuditResult fresh_audit(const InertiaFunction& m, const Eigen::VectorXd& phi, const AuditDomain& d) {
  AuditOptions a;
  a.samples = 8192;
  a.starts = 16;
  a.seed = 987654321;
  return audit_pd(m, phi, d, a);
}

TEST_F(CraneX7Projection, ExchangeLoopPassesTheAllPoseAudit) {
  ProjectionOptions o;
  o.eps = 0.001;
  const ProjectionResult p = project_pd(*m, phi0, domain, o);
  ASSERT_TRUE(p.feasible) << p.status;
  EXPECT_EQ(p.status, "ok");
  EXPECT_EQ(p.eps, 0.001);
  EXPECT_GE(p.rounds, 1);
  EXPECT_LE(p.rounds, o.max_rounds);
  EXPECT_GE(p.lambda_min, o.eps - o.accept_slack);
  const AuditResult a = fresh_audit(*m, p.phi, domain);
  EXPECT_GE(a.lambda_min, o.eps - o.accept_slack) << "at " << a.worst_pose.transpose();
  // A projection: it lands on the margin, not beyond it.
  EXPECT_LT(a.lambda_min, o.eps + 1e-6);
  for (int i = 0; i < Reduced::np; ++i)
    if (is_friction(i)) EXPECT_EQ(p.phi(i), phi0(i)) << Reduced::parameters[i].name;
  EXPECT_NEAR(p.distance, (p.phi - phi0).norm(), 1e-15);
  EXPECT_LT(p.distance, (truth - phi0).norm());  // the truth is feasible at 0.001 everywhere

  // Already feasible at the margin: returned unchanged, without a solve.
  const ProjectionResult same = project_pd(*m, truth, domain, o);
  EXPECT_TRUE(same.feasible);
  EXPECT_EQ(same.phi, truth);
  EXPECT_EQ(same.rounds, 0);
}

TEST_F(CraneX7Projection, ShortfallRaiseTradesDistanceForRounds) {
  ProjectionOptions plain;
  plain.eps = 0.001;
  ProjectionOptions raised = plain;
  raised.shortfall_raise = 0.5;
  const AuditResult a0 = audit_pd(*m, phi0, domain, plain.audit);
  const ProjectionResult p = project_pd(*m, phi0, domain, plain, a0);
  const ProjectionResult q = project_pd(*m, phi0, domain, raised, a0);
  ASSERT_TRUE(p.feasible) << p.status;
  ASSERT_TRUE(q.feasible) << q.status;
  EXPECT_LE(q.rounds, p.rounds);
  EXPECT_GE(q.distance, p.distance * (1 - 1e-9));  // the plain exchange is the closer one...
  EXPECT_LT(q.distance, p.distance * (1 + 1e-3));  // ...by little
  EXPECT_GE(fresh_audit(*m, q.phi, domain).lambda_min, plain.eps - plain.accept_slack);
}

TEST_F(CraneX7Projection, RescueWithZeroMarginIsStrictlyPositive) {
  ProjectionOptions o;
  o.eps = 0;
  const ProjectionResult p = project_pd(*m, phi0, domain, o);
  ASSERT_TRUE(p.feasible) << p.status;
  EXPECT_EQ(p.eps, 0);
  EXPECT_GT(p.lambda_min, 0);
  const AuditResult a = fresh_audit(*m, p.phi, domain);
  EXPECT_GT(a.lambda_min, 0) << "at " << a.worst_pose.transpose();
  EXPECT_LT(a.lambda_min, 1e-6);  // a minimal correction: just inside the PD set
  for (int i = 0; i < Reduced::np; ++i)
    if (is_friction(i)) EXPECT_EQ(p.phi(i), phi0(i));

  // It moves less than the pre-CLIE projection with a margin.
  o.eps = 0.001;
  EXPECT_LT(p.distance, project_pd(*m, phi0, domain, o).distance);
}

TEST_F(CraneX7Projection, ConditionalProjectionFollowsThePaperRule) {
  // PD already: unchanged, no attempt.
  const ConditionalProjection pd = conditional_projection(*m, truth, domain);
  EXPECT_FALSE(pd.projected);
  EXPECT_TRUE(pd.feasible);
  EXPECT_EQ(pd.eps, 0);
  EXPECT_EQ(pd.phi, truth);
  EXPECT_TRUE(pd.attempts.empty());
  EXPECT_GT(pd.audit.lambda_min, 0);

  // Not PD: the margins in ascending order, whatever order they are given in; 0.001 works.
  const ConditionalProjection c = conditional_projection(*m, phi0, domain, {0.01, 0.005, 0.001, 0.002});
  EXPECT_LT(c.audit.lambda_min, 0);
  EXPECT_TRUE(c.projected);
  ASSERT_TRUE(c.feasible);
  EXPECT_EQ(c.eps, 0.001);
  ASSERT_EQ(c.attempts.size(), 1u);
  EXPECT_EQ(c.attempts[0].eps, 0.001);
  EXPECT_EQ(c.phi, c.attempts[0].phi);
  EXPECT_GE(fresh_audit(*m, c.phi, domain).lambda_min, 0.001 - 1e-9);
}

TEST(SdpProjection, ConditionalProjectionAdoptsTheSmallestFeasibleMargin) {
  // M = diag(phi_0, 0.003): no parameter moves the second entry, so margins above 0.003 are
  // infeasible; phi_0 = -1 is not PD.
  std::vector<Eigen::MatrixXd> L{unit(2, 0, 0)};
  const AffineInertia m(Eigen::Vector2d(0, 0.003).asDiagonal().toDenseMatrix(), L);
  AuditDomain d;
  d.lower = Eigen::Vector2d(-1, -1);
  d.upper = Eigen::Vector2d(1, 1);
  const Eigen::VectorXd phi0 = Eigen::VectorXd::Constant(1, -1.0);

  const ConditionalProjection c = conditional_projection(m, phi0, d, {0.005, 0.002, 0.01});
  ASSERT_TRUE(c.feasible);
  EXPECT_EQ(c.eps, 0.002);
  ASSERT_EQ(c.attempts.size(), 1u);
  EXPECT_NEAR(c.phi(0), 0.002, 1e-9);

  const ConditionalProjection none = conditional_projection(m, phi0, d, {0.01, 0.005});
  EXPECT_TRUE(none.projected);
  EXPECT_FALSE(none.feasible);
  ASSERT_EQ(none.attempts.size(), 2u);
  EXPECT_EQ(none.attempts[0].eps, 0.005);  // ascending
  EXPECT_EQ(none.attempts[1].eps, 0.01);
  // Nothing that failed is handed on: the vector is phi_0 and no margin is adopted.
  EXPECT_EQ(none.phi, phi0);
  EXPECT_EQ(none.eps, 0.0);
  for (const auto& a : none.attempts) {
    EXPECT_FALSE(a.feasible);
    EXPECT_NE(a.status, "ok");
  }
}

// ---- The largest models: CRANE-X7 full (8 joints, 65 parameters), RX-90 (6 joints, 52) ----

// OLS from a short noisy log (three sines per joint over amp of the range, 100 Hz, 0.3 N m of
// noise): the poorly excited directions are far off and M is not PD, like a real short run.
template <class Model>
Eigen::VectorXd short_log_ols(const Eigen::VectorXd& truth, double seconds, double amp, unsigned seed) {
  constexpr int n = Model::nq, waves = 3;
  constexpr double kPi = 3.14159265358979323846;
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> noise(0, 0.3);
  Eigen::MatrixXd a(n, waves), f(n, waves), p(n, waves);
  for (int j = 0; j < n; ++j)
    for (int k = 0; k < waves; ++k) {
      a(j, k) = amp * 0.5 * (Model::joints[j].upper - Model::joints[j].lower) / waves * (0.6 + 0.4 * u(gen));
      f(j, k) = 2 * kPi * (0.15 + 0.5 * u(gen));
      p(j, k) = 2 * kPi * u(gen);
    }
  const int rows = static_cast<int>(seconds / 0.01);
  Eigen::MatrixXd W(rows * n, Model::np);
  Eigen::VectorXd tau(rows * n);
  Eigen::Matrix<double, n, 1> q, qd, qdd;
  for (int i = 0; i < rows; ++i) {
    for (int j = 0; j < n; ++j) {
      q(j) = 0.5 * (Model::joints[j].lower + Model::joints[j].upper), qd(j) = qdd(j) = 0;
      for (int k = 0; k < waves; ++k) {
        const double x = f(j, k) * i * 0.01 + p(j, k);
        q(j) += a(j, k) * std::sin(x), qd(j) += a(j, k) * f(j, k) * std::cos(x);
        qdd(j) -= a(j, k) * f(j, k) * f(j, k) * std::sin(x);
      }
    }
    W.middleRows(i * n, n) = Model::regressor(q, qd, qdd);
    tau.segment(i * n, n) = W.middleRows(i * n, n) * truth;
    for (int j = 0; j < n; ++j) tau(i * n + j) += noise(gen);
  }
  return W.colPivHouseholderQr().solve(tau);
}

template <class Model>
class BigModelProjection : public testing::Test {
 protected:
  void SetUp() override {
    if constexpr (std::is_same_v<Model, symoro::rx90::Model>) {
      symoro::test::Random rng(17);
      truth = Model::base_from_standard(symoro::test::random_standard_parameters<Model>(rng).s);
      phi0 = short_log_ols<Model>(truth, 1.0, 0.35, 1);
    } else {
      const auto config = symoro::twin::read_twin_config(SYMORO_ROBOTS_DIR "/crane_x7/twin.yaml", Model::nq);
      truth = symoro::twin::make_truth(symoro::robot::compiled_model<Model>(), config).phi;
      phi0 = short_log_ols<Model>(truth, 2.0, 0.1, 1);
    }
  }
  std::unique_ptr<InertiaFunction> m = identification_model<Model>()->inertia_function();
  AuditDomain domain = audit_domain<Model>();
  Eigen::VectorXd truth, phi0;
};
using BigModels = testing::Types<symoro::crane_x7::Model, symoro::rx90::Model>;
TYPED_TEST_SUITE(BigModelProjection, BigModels);

TYPED_TEST(BigModelProjection, SdpOnManyPosesSolves) {
  // 64 pose blocks: from CSDP's own start (X = 10 alpha I, alpha growing with the blocks) this
  // ended in "lack of progress" or the iteration limit.
  const double eps = 0.001;
  const std::vector<Eigen::VectorXd> poses = random_poses(this->domain, 64, 11);
  ASSERT_LT(lambda_min_over(*this->m, this->phi0, poses), 0);
  ASSERT_GE(lambda_min_over(*this->m, this->truth, poses), eps);
  const ProjectionResult r = project_on_poses(*this->m, this->phi0, poses, eps);
  ASSERT_TRUE(r.feasible) << r.status;
  EXPECT_GE(lambda_min_over(*this->m, r.phi, poses), eps - 1e-8);
  EXPECT_LE(r.distance, (this->truth - this->phi0).norm());
  // A projection: a step back toward phi0 leaves the feasible set.
  EXPECT_LT(lambda_min_over(*this->m, r.phi + 1e-3 * (this->phi0 - r.phi), poses), eps - 1e-9);
}

TYPED_TEST(BigModelProjection, ConditionalProjectionOfShortLogOls) {
  ProjectionOptions o;
  o.shortfall_raise = 0.5;  // as StudyOptions
  const ConditionalProjection c = conditional_projection(*this->m, this->phi0, this->domain, paper_margins(), o);
  ASSERT_LT(c.audit.lambda_min, 0);
  ASSERT_FALSE(c.attempts.empty());
  for (const auto& a : c.attempts)
    std::printf("eps %g: %s, %d rounds, %d poses, lambda_min %.3g, distance %.4g, %.2f s\n", a.eps, a.status.c_str(),
                a.rounds, a.poses, a.lambda_min, a.distance, a.wall);
  ASSERT_TRUE(c.attempts[0].feasible) << c.attempts[0].status;
  ASSERT_TRUE(c.feasible);
  EXPECT_EQ(c.eps, 0.001);
  // Independent checks: brute force over random poses and a fresh audit.
  EXPECT_GE(lambda_min_over(*this->m, c.phi, random_poses(this->domain, 20000, 99)), c.eps - 1e-9);
  const AuditResult a = fresh_audit(*this->m, c.phi, this->domain);
  EXPECT_GE(a.lambda_min, c.eps - 1e-9) << "at " << a.worst_pose.transpose();
  // Not farther than a known feasible point, and near the margin (the raise costs little).
  EXPECT_LT(c.attempts[0].distance, (this->truth - this->phi0).norm());
  EXPECT_LT(a.lambda_min, c.eps + 0.011 * (c.eps - c.audit.lambda_min));
}

}  // namespace
