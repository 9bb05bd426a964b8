// Excitation for any robot folder (compiled once, each robot through its library: also a folder
// the suite has never seen, tools/run_tests.sh): the structured families generated from the
// joints build inside every limit, and an optimized Fourier design from the middle of the box
// meets every limit on a 0.5 ms grid, checked here with the series' own formula and the
// generated inverse dynamics with robot.yaml's nominal parameters (a 0.5 kg link per joint when
// it has none), and excites every base parameter, with a larger log det than the structured
// single-joint trajectory of the same length (and a smaller kappa where that one is poorly
// conditioned). The robot's identified model (robot.yaml's `identified`).
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <unistd.h>

#include <memory>

#include <gtest/gtest.h>

#include "robot_folders.hpp"
#include "symoro/excitation/design.hpp"
#include "symoro/excitation/quality.hpp"
#include "symoro/identify/loaded_model.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/trajectory/structured_design.hpp"

namespace {

namespace fs = std::filesystem;
using namespace symoro;

// Param: a robot folder (robot_folders.hpp).
class Excite : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    const auto lib = test::test_library(GetParam());
    model_ = std::make_unique<robot::ModelHandle>(lib->model(""));
    full_ = std::make_unique<robot::ModelHandle>(lib->model(0));
  }
  const robot::ModelHandle& model() const { return *model_; }  // the identified model
  const robot::ModelHandle& full() const { return *full_; }
  const std::vector<JointInfo>& joints() const { return model_->joints(); }

  bool revolute_only() const {
    for (const auto& j : joints())
      if (j.type != JointType::Revolute) return false;
    return true;
  }

  // robot.yaml's nominal, else every link a 0.5 kg point 0.1 m along its x axis (a made-up arm
  // whose torques are still of a plausible size).
  Eigen::VectorXd nominal_phi() const {
    const YAML::Node nominal = YAML::LoadFile(GetParam() + "/robot.yaml")["nominal"];
    Eigen::VectorXd s = Eigen::VectorXd::Zero(model().ns());
    for (int k = 0; k < model().ns(); ++k) {
      const std::string name = model().standard_parameters()[k].name, family = model().standard_parameters()[k].family;
      if (nominal && nominal[name])
        s(k) = nominal[name].as<double>();
      else if (!nominal && family == "M")
        s(k) = 0.5;
      else if (!nominal && family == "MX")
        s(k) = 0.05;
      else if (!nominal && (family == "XX" || family == "YY" || family == "ZZ"))
        s(k) = 0.01;
    }
    return model().base_from_standard(s);
  }

  trajectory::StructuredDesignOptions structured_options() const {
    trajectory::StructuredDesignOptions o;
    o.robot = model().robot();
    o.joints = joints();
    return o;
  }

 private:
  std::unique_ptr<robot::ModelHandle> model_, full_;
};

TEST_P(Excite, StructuredFamiliesBuildInsideTheLimits) {
  if (!revolute_only()) {  // the design format is in degrees: refused, naming the prismatic joint
    try {
      trajectory::structured_design_yaml(structured_options());
      ADD_FAILURE() << "a robot with a prismatic joint was not refused";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("is prismatic"), std::string::npos) << e.what();
    }
    return;
  }
  const fs::path file = fs::temp_directory_path() / ("symoro_excite_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(file) << trajectory::structured_design_yaml(structured_options());
  const auto design = trajectory::TrajectoryDesign::read(file, joints());
  EXPECT_GE(design.names().size(), 30u);
  for (const auto& name : design.names()) EXPECT_NO_THROW(design.build(name)) << name;  // build() checks the limits
  fs::remove(file);
}

TEST_P(Excite, OptimizedDesignMeetsEveryLimitAndExcitesEveryParameter) {
  const auto identification = identify::identification_model(model(), full());
  const int n = model().nq();
  excitation::ExcitationDesignOptions o;
  trajectory::StructuredDesignOptions so = structured_options();
  Eigen::VectorXd lo(n), hi(n);
  if (revolute_only()) {
    trajectory::structured_box(so, lo, hi);
  } else {
    for (int j = 0; j < n; ++j) lo(j) = joints()[j].lower, hi(j) = joints()[j].upper;
  }
  o.start = (lo + hi) / 2;
  o.limits.lower = lo;
  o.limits.upper = hi;
  o.limits.velocity.resize(n);
  o.limits.torque.resize(n);
  for (int j = 0; j < n; ++j) {
    o.limits.velocity(j) = 0.5 * joints()[j].velocity;
    o.limits.torque(j) = joints()[j].effort;
  }
  o.limits.acceleration = 3.0 * o.limits.velocity;
  o.nominal = nominal_phi();
  o.harmonics = 4;
  o.period = 12;
  o.starts = 2;
  excitation::ExcitationDesign d;
  try {
    d = excitation::design_excitation(*identification, o);
  } catch (const excitation::ExcitationInfeasible& e) {
    FAIL() << "the design from the middle of the box was refused: " << e.what();
  }
  const auto& t = d.trajectory;
  Eigen::VectorXd q, qd, qdd, tau;
  // The starts solved at once, each in a process of its own (the default), give the design
  // solved one after the other in this process, bit for bit (two robots: it costs a design).
  const std::string robot = fs::path(GetParam()).filename().string();
  if (robot == "planar2r" || robot == "ur5") {
    excitation::ExcitationDesignOptions one = o;
    one.workers = 1;
    const excitation::ExcitationDesign serial = excitation::design_excitation(*identification, one);
    ASSERT_EQ(serial.starts.size(), d.starts.size());
    EXPECT_EQ(serial.chosen, d.chosen);
    for (std::size_t s = 0; s < d.starts.size(); ++s) {
      EXPECT_EQ(serial.starts[s].criterion, d.starts[s].criterion) << "start " << s;
      EXPECT_EQ(serial.starts[s].iterations, d.starts[s].iterations) << "start " << s;
      EXPECT_EQ(serial.starts[s].status, d.starts[s].status) << "start " << s;
    }
    Eigen::VectorXd sq, sqd, sqdd;
    for (double time : {0.0, 0.37, 1.9, 7.5}) {
      t.evaluate(time, q, qd, qdd);
      serial.trajectory.evaluate(time, sq, sqd, sqdd);
      EXPECT_EQ(q, sq) << "t = " << time;
      EXPECT_EQ(qdd, sqdd) << "t = " << time;
    }
  }
  double worst = 1e9;
  for (double time = 0; time <= t.period(); time += 5e-4) {
    t.evaluate(time, q, qd, qdd);
    tau = model().inverse_dynamics(q, qd, qdd, o.nominal);
    for (int j = 0; j < n; ++j)
      worst = std::min({worst, hi(j) - q(j), q(j) - lo(j), o.limits.velocity(j) - std::abs(qd(j)),
                        o.limits.acceleration(j) - std::abs(qdd(j)), o.limits.torque(j) - std::abs(tau(j))});
  }
  EXPECT_GE(worst, 0);
  t.evaluate(0, q, qd, qdd);
  EXPECT_LT((q - o.start).norm() + qd.norm() + qdd.norm(), 1e-12);
  const auto optimized = excitation::excitation_quality(*identification, t.sample(0.001), 0.01);
  EXPECT_TRUE(optimized.unexcited.empty());
  EXPECT_TRUE(std::isfinite(optimized.kappa_scaled));
  if (!revolute_only()) return;
  // The structured families' single-joint trajectory, cut to the same length (every joint moves
  // alone, from the posture): the optimized series tells the parameters apart better.
  const fs::path file = fs::temp_directory_path() / ("symoro_excite_q" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(file) << trajectory::structured_design_yaml(so);
  const auto design = trajectory::TrajectoryDesign::read(file, joints());
  fs::remove(file);
  auto singles = trajectory::sample(design.build("PA03"), 0.001);
  const int cycles = std::min(singles.cycles(), static_cast<int>(std::lround(t.period() / 0.001)) + 1);
  singles.q.conservativeResize(Eigen::NoChange, cycles);
  singles.qd.conservativeResize(Eigen::NoChange, cycles);
  singles.qdd.conservativeResize(Eigen::NoChange, cycles);
  const auto structured = excitation::excitation_quality(*identification, singles, 0.01);
  EXPECT_GT(optimized.log_det_scaled, structured.log_det_scaled);
  // D-optimality is not kappa: where the singles are already well conditioned (the planar 2R
  // arm: 4.5) the optimum may trade a little kappa for information; where they are poorly
  // conditioned (every arm of robots/ but the planar one), it must improve kappa too.
  if (structured.kappa_scaled > 10) EXPECT_LT(optimized.kappa_scaled, structured.kappa_scaled);
}

INSTANTIATE_TEST_SUITE_P(Robots, Excite, ::testing::ValuesIn(test::test_robot_folders()), test::folder_test_name);

}  // namespace
