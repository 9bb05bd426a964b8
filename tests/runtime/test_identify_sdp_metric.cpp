// The SDP projection in a full metric (ProjectionOptions::metric, the information metric of
// the study's --projection-metric information) against closed forms: the metric projection onto
// a half-space, and eigenvalue clipping seen through an invertible change of parameters; and on
// CRANE-X7 and the RX-90 against the Euclidean projection (each optimal in its own metric).
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <gtest/gtest.h>

#include <symoro/crane_x7.hpp>
#include <symoro/rx90.hpp>

#include "affine_inertia.hpp"
#include "symoro/identify/identification_model.hpp"  // inertia functions from symoro::<robot>_identification
#include "symoro/identify/sdp_projection.hpp"
#include "symoro/robot/compiled_model.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/truth.hpp"
#include "test_support.hpp"

namespace {

using namespace symoro::identify;
using symoro::test::AffineInertia;

const std::vector<Eigen::VectorXd> kOnePose{Eigen::VectorXd::Zero(1)};

double metric_norm(const Eigen::MatrixXd& A, const Eigen::VectorXd& d) { return std::sqrt(d.dot(A * d)); }

TEST(SdpMetric, HalfSpaceProjectionMovesParametersOutsideM) {
  // 1 x 1 M = 0.1 + phi_0 - 2 phi_1 >= eps; phi_2 (a friction parameter) is not in M, but the
  // metric couples it to phi_0: d = delta A^-1 a / (a' A^-1 a), a = (1, -2, 0).
  const AffineInertia m(
      Eigen::MatrixXd::Constant(1, 1, 0.1),
      {Eigen::MatrixXd::Constant(1, 1, 1.0), Eigen::MatrixXd::Constant(1, 1, -2.0), Eigen::MatrixXd::Zero(1, 1)});
  Eigen::MatrixXd A(3, 3);
  A << 4, 0.5, 1.5, 0.5, 2, 0.2, 1.5, 0.2, 1;
  Eigen::VectorXd phi0(3), a(3);
  phi0 << -0.3, 0.05, 0.7;
  a << 1, -2, 0;
  const double eps = 0.002;
  const double delta = eps - (0.1 + a.dot(phi0));
  const Eigen::VectorXd Ainv_a = A.llt().solve(a);
  const Eigen::VectorXd d = delta * Ainv_a / a.dot(Ainv_a);
  ASSERT_GT(std::abs(d(2)), 0.01);  // the coupling moves the parameter M does not hold
  const ProjectionResult r = project_on_poses(m, phi0, kOnePose, eps, {}, A);
  ASSERT_TRUE(r.feasible) << r.status;
  EXPECT_LT((r.phi - phi0 - d).norm(), 1e-8) << (r.phi - phi0).transpose() << " vs " << d.transpose();
  EXPECT_NEAR(r.distance, metric_norm(A, d), 1e-8);
}

TEST(SdpMetric, ChangeOfParametersGivesEigenvalueClipping) {
  // M(phi) = F(B phi) with F the Frobenius map: in the metric A = B'B the distance is the
  // Frobenius distance of M, so the projection is eigenvalue clipping whatever B is.
  const int n = 3;
  const auto frob = symoro::test::frobenius_model(n);
  const int p = frob.parameters();
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g;
  Eigen::MatrixXd B(p, p);
  for (int i = 0; i < p; ++i)
    for (int j = 0; j < p; ++j) B(i, j) = (i == j ? 2.0 : 0.0) + 0.4 * g(rng);
  ASSERT_GT(std::abs(B.determinant()), 1e-3);
  std::vector<Eigen::MatrixXd> L(p, Eigen::MatrixXd::Zero(n, n)), F;
  Eigen::MatrixXd C;
  frob.basis(Eigen::VectorXd::Zero(n), C, F);
  for (int i = 0; i < p; ++i)
    for (int k = 0; k < p; ++k) L[i] += B(k, i) * F[k];
  const AffineInertia m(C, L);
  const Eigen::Matrix3d M0{{0.2, 0.5, -0.1}, {0.5, 0.1, 0.3}, {-0.1, 0.3, -0.4}};
  const Eigen::VectorXd phi0 = B.partialPivLu().solve(symoro::test::frobenius_params(M0));
  const double eps = 0.01;
  const ProjectionResult r = project_on_poses(m, phi0, {Eigen::VectorXd::Zero(n)}, eps, {}, B.transpose() * B);
  ASSERT_TRUE(r.feasible) << r.status;
  Eigen::MatrixXd M;
  m.inertia(Eigen::VectorXd::Zero(n), r.phi, M);
  EXPECT_LT((M - symoro::test::clip_eigenvalues(M0, eps)).norm(), 1e-7) << M;
}

TEST(SdpMetric, RejectsAMetricThatIsNotPositiveDefinite) {
  const AffineInertia m(Eigen::MatrixXd::Constant(1, 1, 0.1),
                        {Eigen::MatrixXd::Constant(1, 1, 1.0), Eigen::MatrixXd::Constant(1, 1, 1.0)});
  const Eigen::Vector2d phi0(-0.5, 0);
  EXPECT_THROW(project_on_poses(m, phi0, kOnePose, 0.01, {}, Eigen::Matrix2d{{1, 2}, {2, 1}}), std::invalid_argument);
  EXPECT_THROW(project_on_poses(m, phi0, kOnePose, 0.01, {}, Eigen::Matrix3d::Identity()), std::invalid_argument);
  EXPECT_THROW(project_on_poses(m, phi0, kOnePose, 0.01, Eigen::Vector2d(1, 1), Eigen::Matrix2d::Identity()),
               std::invalid_argument);
  EXPECT_THROW(information_metric(Eigen::Matrix2d::Zero()), std::invalid_argument);
}

// On a generated model: the all-pose projection in a random information-like metric and in the
// Euclidean norm, from a non-PD vector; each is PD over the box and no farther than the other in
// its own metric (the exchange loop's working sets differ, so up to a small tolerance).
template <class Model>
void metric_and_euclidean_are_each_optimal(const Eigen::VectorXd& truth, std::uint64_t seed) {
  const auto m = identification_model<Model>()->inertia_function();
  const AuditDomain domain = audit_domain<Model>();
  const int np = Model::np;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  // The information matrix of regressor rows at random states (a short, poorly exciting log).
  using Vec = Eigen::Matrix<double, Model::nq, 1>;
  Eigen::MatrixXd W(Model::nq * 3 * np, np);
  for (int k = 0; k < 3 * np; ++k) {
    Vec q, qd, qdd;
    for (int j = 0; j < Model::nq; ++j) {
      q(j) = std::uniform_real_distribution<double>(domain.lower(j), domain.upper(j))(rng);
      qd(j) = g(rng);
      qdd(j) = 3 * g(rng);
    }
    W.middleRows(k * Model::nq, Model::nq) = Model::regressor(q, qd, qdd);
  }
  const Eigen::MatrixXd A = information_metric(W.transpose() * W / 1e-4);  // noise 0.01 N m
  Eigen::VectorXd dir(np);
  for (int j = 0; j < np; ++j) dir(j) = g(rng) * (std::abs(truth(j)) + 1e-3);
  Eigen::VectorXd phi0 = truth;
  for (double t = 0.1; audit_pd(*m, phi0, domain).positive_definite(); t *= 1.5) phi0 = truth + t * dir;

  ProjectionOptions euclid;
  euclid.eps = 0.001;
  ProjectionOptions info = euclid;
  info.metric = A;
  const ProjectionResult e = project_pd(*m, phi0, domain, euclid);
  const ProjectionResult i = project_pd(*m, phi0, domain, info);
  ASSERT_TRUE(e.feasible) << e.status;
  ASSERT_TRUE(i.feasible) << i.status;
  EXPECT_GE(audit_pd(*m, i.phi, domain).lambda_min, 0.001 - 1e-9);
  EXPECT_NEAR(i.distance, metric_norm(A, i.phi - phi0), 1e-9 * (1 + i.distance));
  EXPECT_LE(metric_norm(A, i.phi - phi0), metric_norm(A, e.phi - phi0) * (1 + 1e-3));
  EXPECT_LE((e.phi - phi0).norm(), (i.phi - phi0).norm() * (1 + 1e-3));
  // The two answers are different points: the metric matters.
  EXPECT_GT((i.phi - e.phi).norm(), 1e-3 * (e.phi - phi0).norm());
}

TEST(SdpMetric, CraneX7ReducedEachProjectionIsOptimalInItsMetric) {
  using Model = symoro::crane_x7::reduced::Model;
  const std::string robot = std::string(SYMORO_ROBOTS_DIR) + "/crane_x7";
  const auto tc = symoro::twin::read_twin_config(robot + "/twin.yaml", symoro::crane_x7::Model::nq);
  const Eigen::VectorXd truth = Model::base_from_standard(
      symoro::twin::make_truth(symoro::robot::compiled_model<symoro::crane_x7::Model>(), tc).standard);
  metric_and_euclidean_are_each_optimal<Model>(truth, 3);
}

TEST(SdpMetric, Rx90EachProjectionIsOptimalInItsMetric) {
  using Model = symoro::rx90::Model;
  symoro::test::Random rng(17);
  const Eigen::VectorXd truth = Model::base_from_standard(symoro::test::random_standard_parameters<Model>(rng).s);
  metric_and_euclidean_are_each_optimal<Model>(truth, 5);
}

}  // namespace
