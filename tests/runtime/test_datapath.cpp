// The measured-data path end to end: the twin's log, written and read back, preprocessed at the
// paper's four intervals, must satisfy the rigid-body model with the twin's true parameters:
// the logged torque (from quantized current) against inverse dynamics at the estimated
// (q, qd, qdd). What remains is the measurement floor (current quantization and noise,
// encoder quantization through the derivatives) plus the products of the filter with a
// nonlinear model, which must stay small next to the torques themselves.
#include <cmath>
#include <filesystem>
#include <iostream>

#include <gtest/gtest.h>

#include <symoro/crane_x7.hpp>

#include "symoro/io/log.hpp"
#include "symoro/preprocess/preprocess.hpp"
#include "symoro/robot/compiled_model.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/simulator.hpp"

namespace {

using Model = symoro::crane_x7::Model;
constexpr int n = Model::nq;
const std::string kRobot = std::string(SYMORO_ROBOTS_DIR) + "/crane_x7";

TEST(DataPath, TwinLogThroughPreprocessingSatisfiesTheTrueModel) {
  const auto config = symoro::twin::read_twin_config(kRobot + "/twin.yaml", n);  // noise, jitter, drops
  const symoro::twin::ClosedLoopTwin twin(symoro::robot::compiled_model<Model>(), config);
  const auto design = symoro::trajectory::TrajectoryDesign::read(
      kRobot + "/trajectories.yaml", std::vector<symoro::JointInfo>(Model::joints.begin(), Model::joints.end()));
  const auto dir = std::filesystem::temp_directory_path() / "symoro_datapath_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);

  for (const std::string name : {"AP01", "PC03"}) {
    symoro::twin::RunOptions ro;
    ro.robot = "crane_x7";
    ro.seed = symoro::twin::run_seed(3, name, 1);
    symoro::twin::RunStats st;
    const auto log = twin.run(design.build(name), ro, &st);
    const auto file = dir / (name + "_t1.csv");
    symoro::io::write_log(file, log);
    const auto back = symoro::io::read_log(file);
    ASSERT_EQ(back.samples(), log.samples());
    ASSERT_EQ(back.tau, log.tau);

    for (double interval : symoro::preprocess::paper_intervals()) {
      const auto s = symoro::preprocess::preprocess(back, interval);
      // Every dropped row was bridged, none silently lost.
      EXPECT_EQ(s.report.missing_samples, st.dropped) << s.report.summary();
      const double span = log.time(log.samples() - 1) - log.time(0);
      EXPECT_NEAR(double(s.time.size()), std::floor(span / interval) + 1, 2) << s.report.summary();
      Eigen::VectorXd sq_res = Eigen::VectorXd::Zero(n), sq_tau = Eigen::VectorXd::Zero(n);
      for (int k = 0; k < s.time.size(); ++k) {
        Eigen::Matrix<double, n, 1> tau;
        Model::inverse_dynamics(s.q.row(k).transpose(), s.qd.row(k).transpose(), s.qdd.row(k).transpose(),
                                twin.truth().phi, tau);
        sq_res += (tau - s.tau.row(k).transpose()).cwiseAbs2();
        sq_tau += s.tau.row(k).transpose().cwiseAbs2();
      }
      const Eigen::VectorXd rms_res = (sq_res / s.time.size()).cwiseSqrt(),
                            rms_tau = (sq_tau / s.time.size()).cwiseSqrt();
      std::cout << name << " at " << interval * 1e3 << " ms: rms residual / rms torque (N m):";
      for (int j = 0; j < n; ++j) std::cout << " " << rms_res(j) << "/" << rms_tau(j);
      std::cout << "\n";
      // Measured floor: up to 7 % of the torque on joint 2 (the filter applied to the torque
      // versus the model applied to filtered motion: gravity and inertia are nonlinear in q)
      // and about 0.003 N m where torques are small (current quantization and noise). A
      // shifted, mis-scaled or mis-ordered column would exceed it by far.
      for (int j = 0; j < n; ++j) EXPECT_LT(rms_res(j), 0.08 * rms_tau(j) + 0.01) << name << " joint " << j + 1;
    }
  }
  std::filesystem::remove_all(dir);
}

// The same comparison fails when the data path is wrong: torque one interval late.
TEST(DataPath, AShiftedTorqueIsNoticed) {
  const auto config = symoro::twin::read_twin_config(kRobot + "/twin.yaml", n);
  const symoro::twin::ClosedLoopTwin twin(symoro::robot::compiled_model<Model>(), config);
  const auto design = symoro::trajectory::TrajectoryDesign::read(
      kRobot + "/trajectories.yaml", std::vector<symoro::JointInfo>(Model::joints.begin(), Model::joints.end()));
  symoro::twin::RunOptions ro;
  auto log = twin.run(design.build("AP01"), ro);
  const auto s = symoro::preprocess::preprocess(log, 0.04);
  double res = 0, tau2 = 0;
  for (int k = 1; k < s.time.size(); ++k) {
    Eigen::Matrix<double, n, 1> tau;
    Model::inverse_dynamics(s.q.row(k).transpose(), s.qd.row(k).transpose(), s.qdd.row(k).transpose(), twin.truth().phi,
                            tau);
    res += std::pow(tau(1) - s.tau(k - 1, 1), 2);
    tau2 += std::pow(s.tau(k, 1), 2);
  }
  EXPECT_GT(std::sqrt(res / tau2), 0.08);
}

}  // namespace
