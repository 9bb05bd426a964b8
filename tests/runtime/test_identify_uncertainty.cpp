// Prediction bands (study/prediction_band.hpp) and the covariance under them
// (identify/hac_covariance.hpp): the Newey-West standard deviations against the spread of
// least-squares estimates over many noise draws with autocorrelated noise, where the textbook
// sigma^2 (X'X)^-1 claims several times too much; and the 95 % band's coverage on held-out runs
// of the twin (CRANE-X7) and of the independent arm (RX-90, data the twin did not make), the
// parameters fitted on another run.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <symoro/crane_x7.hpp>
#include <symoro/rx90.hpp>

#include "independent_arm.hpp"
#include "independent_rx90.hpp"
#include "symoro/identify/hac_covariance.hpp"
#include "symoro/identify/identification_model.hpp"
#include "symoro/identify/least_squares.hpp"
#include "symoro/preprocess/preprocess.hpp"
#include "symoro/robot/compiled_model.hpp"
#include "symoro/study/options.hpp"
#include "symoro/study/prediction_band.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/simulator.hpp"

namespace {

using namespace symoro;
using Crane = crane_x7::Model;
using Rx = rx90::Model;

TEST(HacCovariance, MatchesTheSpreadOfEstimatesUnderAutocorrelatedNoise) {
  // y = X beta + e, 2 "joints" per sample, e an AR(1) series per joint (rho 0.8: the samples of a
  // low-passed residual), X smooth (sines): the estimates' spread over 400 draws against the
  // mean Newey-West standard deviation, and against the textbook one.
  const int N = 1500, joints = 2, p = 3, draws = 400;
  Eigen::MatrixXd X(N * joints, p);
  for (int k = 0; k < N; ++k)
    for (int j = 0; j < joints; ++j) {
      const double t = 0.01 * k;
      X.row(k * joints + j) << 1, std::sin(0.7 * t + j), std::cos(1.9 * t - j);
    }
  const std::vector<int> segment(N, 0);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g;
  const double rho = 0.8;
  Eigen::MatrixXd estimates(draws, p);
  Eigen::VectorXd hac_sd = Eigen::VectorXd::Zero(p), ols_sd = hac_sd;
  const Eigen::MatrixXd XtXi = (X.transpose() * X).inverse();
  for (int d = 0; d < draws; ++d) {
    Eigen::VectorXd e(N * joints);
    Eigen::Vector2d state(g(rng), g(rng));
    for (int k = 0; k < N; ++k) {
      for (int j = 0; j < joints; ++j) {
        state(j) = rho * state(j) + std::sqrt(1 - rho * rho) * g(rng);
        e(k * joints + j) = (j + 1) * 0.1 * state(j);
      }
    }
    const Eigen::VectorXd beta = XtXi * X.transpose() * e;  // the truth is 0
    estimates.row(d) = beta.transpose();
    const Eigen::VectorXd r = e - X * beta;
    const int lags = identify::residual_lags(r, segment, joints);
    hac_sd += identify::hac_covariance(X, r, segment, joints, lags).diagonal().cwiseSqrt() / draws;
    ols_sd += (r.squaredNorm() / (N * joints - p) * XtXi).diagonal().cwiseSqrt() / draws;
  }
  const Eigen::VectorXd spread = (estimates.colwise().squaredNorm() / draws).cwiseSqrt().transpose();
  for (int i = 0; i < p; ++i) {
    EXPECT_NEAR(hac_sd(i) / spread(i), 1.0, 0.2) << "parameter " << i;
    // The textbook deviation is about sqrt((1 - rho) / (1 + rho)) = 1/3 of the truth.
    EXPECT_LT(ols_sd(i) / spread(i), 0.5) << "parameter " << i;
  }
}

TEST(HacCovariance, EqualsTheLagByLagSumWithinEachLog) {
  // The sliding-sum form against the definition: S = sum_k s_k s_k' + sum_{l=1..L} (1 - l / (L + 1))
  // (G_l + G_l'), G_l over pairs of samples of one log; two logs of 300 and 200 samples.
  const int N = 500, joints = 3, p = 4, lags = 17;
  std::mt19937_64 rng(9);
  std::normal_distribution<double> g;
  Eigen::MatrixXd X(N * joints, p);
  Eigen::VectorXd e(N * joints);
  for (Eigen::Index i = 0; i < X.size(); ++i) X.data()[i] = g(rng);
  for (Eigen::Index i = 0; i < e.size(); ++i) e(i) = g(rng) + (i > joints ? 0.7 * e(i - joints) : 0.0);
  std::vector<int> segment(N, 0);
  for (int k = 300; k < N; ++k) segment[static_cast<std::size_t>(k)] = 1;
  Eigen::MatrixXd scores(p, N);
  for (int k = 0; k < N; ++k)
    scores.col(k) = X.middleRows(k * joints, joints).transpose() * e.segment(k * joints, joints);
  Eigen::MatrixXd S = scores * scores.transpose();
  for (int l = 1; l <= lags; ++l)
    for (int k = l; k < N; ++k)
      if (segment[static_cast<std::size_t>(k)] == segment[static_cast<std::size_t>(k - l)]) {
        const Eigen::MatrixXd G = scores.col(k) * scores.col(k - l).transpose();
        S += (1 - static_cast<double>(l) / (lags + 1)) * (G + G.transpose());
      }
  const Eigen::MatrixXd Bi = (X.transpose() * X).inverse();
  const Eigen::MatrixXd expected = Bi * S * Bi;
  const Eigen::MatrixXd got = identify::hac_covariance(X, e, segment, joints, lags);
  EXPECT_LT((got - expected).norm(), 1e-10 * expected.norm());
}

// phi by least squares on `fit`, its uncertainty there, and the 95 % band's coverage on `held`.
template <class Model>
double held_out_coverage(const std::vector<io::Log>& fit, const io::Log& held, const char* what) {
  const auto model = identify::identification_model<Model>();
  const auto po = study::StudyOptions{}.preprocess;
  std::vector<preprocess::Samples> samples;
  identify::Regression all;
  all.joints = Model::nq;
  for (const auto& log : fit) {
    samples.push_back(preprocess::preprocess(log, 0.010, po));
    const identify::Regression r = model->stack_regression(samples.back());
    all.W.conservativeResize(all.W.rows() + r.W.rows(), r.W.cols());
    all.W.bottomRows(r.W.rows()) = r.W;
    all.y.conservativeResize(all.y.size() + r.y.size());
    all.y.tail(r.y.size()) = r.y;
    all.samples += r.samples;
  }
  const Eigen::VectorXd phi = identify::least_squares(all).phi;
  const study::PredictionUncertainty u = study::prediction_uncertainty(*model, samples, phi, what);
  const preprocess::Samples s = preprocess::preprocess(held, 0.010, po);
  const Eigen::MatrixXd band = study::prediction_band(*model, s, u, 0.95);
  const study::BandCoverage c = study::band_coverage(s.tau, model->open_loop_torque(s, phi), band);
  std::printf("%s: %.1f %% of %d held-out samples inside the 95 %% band (lags %d); per joint:", what, 100 * c.all,
              c.samples, u.lags);
  for (Eigen::Index j = 0; j < c.joint.size(); ++j) std::printf(" %.1f", 100 * c.joint(j));
  std::printf("\n");
  // The band is more than the residual alone: the parameters' term is there.
  EXPECT_GT(band.col(0).maxCoeff(), 1.96 * u.residual(0) * 1.0001) << what;
  return c.all;
}

TEST(PredictionBand, HoldsAbout95PercentOfTheTwinsHeldOutTorque) {
  const std::string dir = std::string(SYMORO_ROBOTS_DIR) + "/crane_x7";
  const twin::TwinConfig c = twin::read_twin_config(dir + "/twin.yaml", Crane::nq);
  static const auto design = trajectory::TrajectoryDesign::read(
      dir + "/trajectories.yaml", std::vector<JointInfo>(Crane::joints.begin(), Crane::joints.end()));
  const auto run = [&](const std::string& name, std::uint64_t seed) {
    twin::RunOptions o;
    o.robot = "crane_x7";
    o.seed = seed;
    return twin::ClosedLoopTwin(robot::compiled_model<Crane>(), c).run(design.build(name), o);
  };
  const io::Log fit = run("PA11", 11);
  for (const auto& [name, seed] : std::vector<std::pair<std::string, std::uint64_t>>{{"V01", 12}, {"V02", 13}}) {
    const double coverage = held_out_coverage<Crane>({fit}, run(name, seed), ("crane_x7 twin " + name).c_str());
    EXPECT_GE(coverage, 0.90) << name;
    EXPECT_LE(coverage, 0.98) << name;
  }
}

TEST(PredictionBand, HoldsAbout95PercentOfTheIndependentArmsHeldOutTorque) {
  const twin::TwinConfig arm = test::rx90_twin();
  test::IndependentArmOptions o;
  o.coulomb = Eigen::VectorXd::Constant(Rx::nq, 0.5);  // friction the full model holds (FS)
  std::vector<io::Log> fit;
  for (unsigned seed : {71u, 72u}) {
    o.seed = seed;
    fit.push_back(test::run_independent_arm<Rx>(arm, test::rx90_reference("fit", 20, seed), o));
  }
  o.seed = 73;
  const io::Log held = test::run_independent_arm<Rx>(arm, test::rx90_reference("held", 20, 73), o);
  const double coverage = held_out_coverage<Rx>(fit, held, "rx90 independent arm");
  EXPECT_GE(coverage, 0.90);
  EXPECT_LE(coverage, 0.98);
}

}  // namespace
