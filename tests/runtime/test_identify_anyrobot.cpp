// The identification study on robots without a digital twin, a trajectory design or a
// controller description (only their robots/ folder), from logs synthesized here with the
// generated model: a smooth multi-sine excitation through the joint range, irregular stamps, 5 %
// stale rows (the logger read the same state twice), measured torque with noise and a hidden
// constant offset the model has no term for. The chain must run OLS, audit and SDP, skip CLIE
// and say why, select among the final vectors, validate open loop, and come within the data's
// own floor (the truth's open-loop torque against the same measurement) on a held-out run. Run
// on the 6-DoF RX-90 and the planar 2R arm.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>

#include <symoro/planar2r.hpp>
#include <symoro/rx90.hpp>

#include "symoro/identify/study.hpp"
#include "symoro/io/atomic_file.hpp"
#include "symoro/io/log.hpp"
#include "test_support.hpp"

namespace {

using namespace symoro;

constexpr double kPi = 3.14159265358979323846;

// One synthesized log: q(t) a sum of three sines per joint around the middle of its range.
template <class Model>
io::Log synthesize(const std::string& name, const Eigen::Matrix<double, Model::np, 1>& phi, double seconds,
                   unsigned seed, double noise, double offset, int offset_joint) {
  using Vec = Eigen::Matrix<double, Model::nq, 1>;
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> gauss(0, 1);
  constexpr int n = Model::nq, waves = 3;
  Eigen::MatrixXd amp(n, waves), freq(n, waves), phase(n, waves);
  Eigen::VectorXd mid(n);
  for (int j = 0; j < n; ++j) {
    const auto& J = Model::joints[j];
    mid(j) = 0.5 * (J.lower + J.upper);
    for (int k = 0; k < waves; ++k) {
      amp(j, k) = 0.35 * 0.5 * (J.upper - J.lower) / waves * (0.6 + 0.4 * u(gen));
      freq(j, k) = 2 * kPi * (0.15 + 0.5 * u(gen));
      phase(j, k) = 2 * kPi * u(gen);
    }
  }
  const int rows = static_cast<int>(seconds / 0.001);
  io::Log log;
  log.meta.robot = Model::robot_name;
  log.meta.trajectory = name;
  log.meta.trial = 1;
  log.meta.source = "robot";
  log.meta.sample_time = 0.001;
  for (const auto& J : Model::joints) log.meta.joints.emplace_back(J.name);
  log.time.resize(rows);
  log.q.resize(rows, n);
  log.qd.resize(rows, n);
  log.tau.resize(rows, n);
  Vec q, qd, qdd, tau;
  for (int i = 0; i < rows; ++i) {
    // Stamps: 1 ms apart with +-0.15 ms of jitter; the log starts at 12.5 s (a controller's clock).
    log.time(i) = 12.5 + 0.001 * i + (i > 0 ? 0.00015 * (2 * u(gen) - 1) : 0.0);
    if (i > 0 && u(gen) < 0.05) {  // a stale row: the previous state again, under a new stamp
      log.q.row(i) = log.q.row(i - 1);
      log.qd.row(i) = log.qd.row(i - 1);
      log.tau.row(i) = log.tau.row(i - 1);
      continue;
    }
    const double t = log.time(i);
    for (int j = 0; j < n; ++j) {
      q(j) = mid(j), qd(j) = 0, qdd(j) = 0;
      for (int k = 0; k < waves; ++k) {
        const double w = freq(j, k), a = amp(j, k), arg = w * t + phase(j, k);
        q(j) += a * std::sin(arg);
        qd(j) += a * w * std::cos(arg);
        qdd(j) -= a * w * w * std::sin(arg);
      }
    }
    Model::inverse_dynamics(q, qd, qdd, phi, tau);
    tau(offset_joint) += offset;
    for (int j = 0; j < n; ++j) tau(j) += noise * gauss(gen);
    log.q.row(i) = q.transpose();
    log.qd.row(i) = qd.transpose();
    log.tau.row(i) = tau.transpose();
  }
  return log;
}

template <class Model>
class AnyRobotStudy : public ::testing::Test {
 protected:
  using Phi = Eigen::Matrix<double, Model::np, 1>;

  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           (std::string("symoro_anyrobot_") + Model::robot_name + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_ / "data");
    test::Random rng(17);
    truth_ = Model::base_from_standard(test::random_standard_parameters<Model>(rng).s);
    std::string manifest = "format: symoro-dataset 1\nrobot: " + std::string(Model::robot_name) + "\nruns:\n";
    const char* names[] = {"R1", "R2", "H1"};
    for (int r = 0; r < 3; ++r) {
      const io::Log log = synthesize<Model>(names[r], truth_, 30.0, 100 + r, kNoise, kOffset, 1);
      io::write_log(dir_ / "data" / (std::string(names[r]) + ".csv"), log);
      manifest += fmt::format("  - {{trajectory: {}, family: {}, trial: 1, file: {}.csv}}\n", names[r], r < 2 ? "F" : "V",
                              names[r]);
    }
    io::write_file_atomically(dir_ / "data" / "dataset.yaml", manifest);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  identify::StudyOptions options() const {
    identify::StudyOptions o;
    o.data = dir_ / "data";
    o.out = dir_ / "study";
    o.intervals = {0.010, 0.020};
    o.threads = 2;
    return o;
  }

  static identify::ClosedLoopSource no_controller() {
    identify::ClosedLoopSource none;  // move-only (a trajectory design is)
    none.why = "no controller description (test)";
    return none;
  }

  static constexpr double kNoise = 0.05, kOffset = 0.08;
  std::filesystem::path dir_;
  Phi truth_;
};

using Robots = ::testing::Types<rx90::Model, planar2r::Model>;
TYPED_TEST_SUITE(AnyRobotStudy, Robots);

TYPED_TEST(AnyRobotStudy, RunsWithoutTwinDesignOrControllerAndValidatesOpenLoop) {
  using Model = TypeParam;
  identify::Study<Model> study(this->options(), this->no_controller());
  const identify::StudyResult r = study.run();

  ASSERT_EQ(r.runs.size(), 4u);  // R1 and R2 at 10 and 20 ms
  for (const auto& run : r.runs) {
    EXPECT_FALSE(run.failed) << run.id() << ": " << run.failure;
    EXPECT_FALSE(run.clie_ran) << run.id();
    EXPECT_NE(run.clie_termination.find("no controller description (test)"), std::string::npos) << run.clie_termination;
    EXPECT_EQ(run.phi_clie, run.phi_sdp) << run.id();  // the chain ends at the SDP (or the PD OLS estimate)
    EXPECT_EQ(run.t_clie, 0.0);
  }
  std::string stages;
  for (const auto& s : r.stages) stages += s + "\n";
  EXPECT_NE(stages.find("CLIE: 0 runs; skipped in 4"), std::string::npos) << stages;

  ASSERT_GE(r.selection.run, 0) << r.selection.rule;
  EXPECT_NE(r.selection.rule.find("CLIE not run"), std::string::npos) << r.selection.rule;
  EXPECT_TRUE(r.accepted) << "final lambda_min " << r.final_lambda_min;

  // Held-out H1, open loop, against the truth's own torque on the same measurement.
  ASSERT_EQ(r.validation.size(), 1u);
  const identify::ValidationRecord& v = r.validation[0];
  EXPECT_EQ(v.trajectory, "H1");
  EXPECT_EQ(v.kind, "open-loop");
  EXPECT_NE(v.note.find("no controller description (test)"), std::string::npos) << v.note;
  preprocess::Samples s;
  s.interval = v.interval;
  s.q = v.q;
  s.qd = v.qd;
  s.qdd = v.qdd;
  s.tau = v.tau_measured;
  const Eigen::MatrixXd floor_tau = identify::open_loop_torque<Model>(s, this->truth_);
  const double floor = identify::torque_error(v.tau_measured, floor_tau).rmse;
  // The floor is the hidden offset (on one of n joints) and the filtered noise: known sizes.
  EXPECT_GT(floor, 0.5 * this->kOffset / std::sqrt(double(Model::nq)));
  EXPECT_LT(floor, 2.0 * std::hypot(this->kOffset / std::sqrt(double(Model::nq)), this->kNoise));
  EXPECT_LT(v.rmse_rescue, 1.5 * floor) << "floor " << floor;
  ASSERT_EQ(v.nrmse_joint_rescue.size(), Model::nq);
  for (int j = 0; j < Model::nq; ++j) {
    const double rms = std::sqrt(v.tau_measured.col(j).squaredNorm() / v.tau_measured.rows());
    EXPECT_NEAR(v.nrmse_joint_rescue(j), v.rmse_joint_rescue(j) / rms, 1e-12);
  }

  // A rerun skips every run and gives the same accepted vector.
  identify::Study<Model> again(this->options(), this->no_controller());
  const identify::StudyResult r2 = again.run();
  EXPECT_EQ(r2.phi_rescue, r.phi_rescue);
}

TYPED_TEST(AnyRobotStudy, AFailingRunIsRecordedAndTheStudyGoesOn) {
  using Model = TypeParam;
  // R3: 40 ms of log, too short for the 10 ms interval's filter; listed twice (--only R1,R3,R3).
  const io::Log shortlog = synthesize<Model>("R3", this->truth_, 0.04, 7, this->kNoise, 0, 0);
  io::write_log(this->dir_ / "data" / "R3.csv", shortlog);
  {
    std::ofstream m(this->dir_ / "data" / "dataset.yaml", std::ios::app);
    m << "  - {trajectory: R3, family: F, trial: 1, file: R3.csv}\n";
  }
  identify::StudyOptions o = this->options();
  o.trajectories = {"R1", "R3", "R3"};
  o.intervals = {0.010};
  identify::Study<Model> study(o, identify::ClosedLoopSource{});
  const identify::StudyResult r = study.run();
  ASSERT_EQ(r.runs.size(), 2u);  // R3 once
  EXPECT_FALSE(r.runs[0].failed);
  EXPECT_TRUE(r.runs[1].failed);
  EXPECT_NE(r.runs[1].failure.find("too short"), std::string::npos) << r.runs[1].failure;
  EXPECT_EQ(r.selection.run, 0);  // the study went on to a representative
  std::string stages;
  for (const auto& s : r.stages) stages += s + "\n";
  EXPECT_NE(stages.find("failed runs: 1 (R3@10ms"), std::string::npos) << stages;
  EXPECT_FALSE(std::filesystem::exists(this->dir_ / "study" / "runs" / "R3@10ms.yaml"));  // tried again next time
}

}  // namespace
