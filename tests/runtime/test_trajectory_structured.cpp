// The structured families for any robot (trajectory/structured_design.hpp) and Fourier series in
// the design format: CRANE-X7's hand-written grid (PA/PB/PC 01-09, AP01-05) rebuilt through the
// generator from the file's own postures, amplitudes, limits and classes; generated designs for
// the UR5 and the RX-90 that build inside every limit; a Fourier item read back bit for bit,
// at rest at both ends; its errors named by line and joint.
#include <symoro/crane_x7.hpp>
#include <symoro/rx90.hpp>
#include <symoro/ur5.hpp>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>
#include <unistd.h>

#include "../removed_at_exit.hpp"
#include "symoro/error.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/trajectory/fourier.hpp"
#include "symoro/trajectory/structured_design.hpp"

namespace symoro::trajectory {
namespace {

namespace fs = std::filesystem;
constexpr double kDeg = 3.14159265358979323846 / 180.0;
const fs::path kCraneFile = fs::path(SYMORO_ROBOTS_DIR) / "crane_x7" / "trajectories.yaml";

template <class Model>
std::vector<JointInfo> joints_of() {
  return {Model::joints.begin(), Model::joints.end()};
}

fs::path write_temp(const std::string& name, const std::string& text) {
  const fs::path dir = symoro::test::removed_at_exit("symoro_structured_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / name) << text;
  return dir / name;
}

Eigen::VectorXd degrees(const YAML::Node& list) {
  Eigen::VectorXd v(list.size());
  for (std::size_t k = 0; k < list.size(); ++k) v[static_cast<Eigen::Index>(k)] = list[k].as<double>() * kDeg;
  return v;
}

void expect_same_motion(const Trajectory& a, const Trajectory& b) {
  ASSERT_EQ(a.segments.size(), b.segments.size()) << a.name;
  EXPECT_NEAR(a.duration(), b.duration(), 1e-9) << a.name;
  const int n = a.joints();
  Eigen::VectorXd qa(n), qda(n), qdda(n), qb(n), qdb(n), qddb(n);
  for (double t = 0; t <= a.duration(); t += 0.01) {
    a.evaluate(t, qa, qda, qdda);
    b.evaluate(t, qb, qdb, qddb);
    ASSERT_LT((qa - qb).cwiseAbs().maxCoeff() + (qda - qdb).cwiseAbs().maxCoeff() + (qdda - qddb).cwiseAbs().maxCoeff(),
              1e-9)
        << a.name << " at t = " << t;
  }
}

TEST(StructuredDesign, RebuildsCraneX7sHandWrittenGrid) {
  const YAML::Node f = YAML::LoadFile(kCraneFile.string());
  StructuredDesignOptions o;
  o.robot = "crane_x7";
  o.joints = joints_of<crane_x7::Model>();
  o.position_margin = f["limits"]["position_margin"].as<double>() * kDeg;
  for (const char* p : {"A", "B", "C"}) {
    o.postures[p] = degrees(f["postures"][p]);
    o.primitives[p] = {degrees(f["primitives"][p]["amplitude"]), degrees(f["primitives"][p]["center"])};
  }
  o.velocity = degrees(f["limits"]["velocity"]) / kDeg;
  o.acceleration = degrees(f["limits"]["acceleration"]) / kDeg;
  o.speed_factors.clear();
  for (const auto& c : f["speed_factors"])
    o.speed_factors[c.first.as<std::string>()] = c.second.as<std::vector<double>>();
  o.joint_class = f["joint_class"].as<std::vector<std::string>>();
  const auto hand = TrajectoryDesign::read(kCraneFile, o.joints);
  const auto generated = TrajectoryDesign::read(write_temp("crane.yaml", structured_design_yaml(o)), o.joints);
  int compared = 0;
  for (const auto& name : generated.names()) {
    if (name[0] == 'V') continue;  // the validation motions are drawn, not the paper's
    expect_same_motion(hand.build(name), generated.build(name));
    ++compared;
  }
  EXPECT_EQ(compared, 3 * 9 + 5);
}

template <class Model>
void expect_generic_design_builds() {
  StructuredDesignOptions o;
  o.robot = Model::robot_name;
  o.joints = joints_of<Model>();
  const std::string text = structured_design_yaml(o);
  const auto d = TrajectoryDesign::read(write_temp(std::string(Model::robot_name) + ".yaml", text), o.joints);
  Eigen::VectorXd lo, hi;
  structured_box(o, lo, hi);
  // 9 per posture, AP at 3 postures + 2, 3 validation; build() checks position and velocity.
  ASSERT_EQ(d.names().size(), 3u * 9 + 5 + 3) << text;
  const int n = Model::nq;
  Eigen::VectorXd q(n), qd(n), qdd(n), moved = Eigen::VectorXd::Zero(n);
  for (const auto& name : d.names()) {
    const Trajectory t = d.build(name);
    Eigen::VectorXd q0(n);
    t.evaluate(0, q0, qd, qdd);
    for (double time = 0; time <= t.duration(); time += 0.02) {
      t.evaluate(time, q, qd, qdd);
      for (int j = 0; j < n; ++j) {
        EXPECT_GE(q(j), lo(j) - 1e-9) << name << " joint " << j + 1;
        EXPECT_LE(q(j), hi(j) + 1e-9) << name << " joint " << j + 1;
        EXPECT_LE(std::abs(qd(j)), Model::joints[j].velocity) << name;
        if (name == "PA01") moved(j) = std::max(moved(j), std::abs(q(j) - q0(j)));
      }
    }
  }
  // Every joint swings in the singles, by a sizable part of its box (at most 60 deg).
  for (int j = 0; j < n; ++j)
    EXPECT_GT(moved(j), std::min(0.3 * (hi(j) - lo(j)), 0.9 * 60 * kDeg)) << "joint " << j + 1;
}

TEST(StructuredDesign, GenericDesignsBuildInsideTheLimitsOnTwoRobots) {
  expect_generic_design_builds<ur5::Model>();
  expect_generic_design_builds<rx90::Model>();
}

// A series at rest at t = 0, written into a design next to CRANE-X7's postures.
FourierTrajectory random_series(int n, int harmonics, double period, double size, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  FourierTrajectory t;
  t.w = 2 * 3.14159265358979323846 / period;
  t.a.resize(n, harmonics);
  t.b.resize(n, harmonics);
  for (int j = 0; j < n; ++j)
    for (int l = 0; l < harmonics; ++l) t.a(j, l) = size * g(rng), t.b(j, l) = size * g(rng);
  t.come_to_rest_at(Eigen::VectorXd::Zero(n));
  return t;
}

std::string crane_with(const std::string& entries) {
  std::ifstream in(kCraneFile);
  std::stringstream all;
  all << in.rdbuf();
  return all.str() + "\n" + entries;
}

TEST(FourierInDesign, ReadsBackBitForBitAndRestsAtBothEnds) {
  const auto joints = joints_of<crane_x7::Model>();
  FourierTrajectory series = random_series(8, 4, 7.5, 0.05, 2);
  series.a.row(7).setZero();  // the hand rests 3 deg above its stop (less the margin) at posture A
  series.b.row(7).setZero();
  const auto d = TrajectoryDesign::read(
      write_temp("fourier.yaml", crane_with(fourier_trajectory_yaml("OF01", "A", series, 2, "a test series"))), joints);
  const Trajectory t = d.build("OF01");
  EXPECT_EQ(t.family, "OF");
  // hold 1.5 s, 2 periods, end hold 1.5 s (the trailing dwell dropped).
  EXPECT_NEAR(t.duration(), 1.5 + 2 * 7.5 + 1.5, 1e-9);
  const Eigen::VectorXd A = degrees(YAML::LoadFile(kCraneFile.string())["postures"]["A"]);
  Eigen::VectorXd q(8), qd(8), qdd(8), sq, sqd, sqdd;
  for (double time : {0.0, 1.5, 9.0, 16.5, 18.0}) {
    t.evaluate(time, q, qd, qdd);
    if (time == 0.0 || time == 1.5 || time == 16.5 || time == 18.0) {
      EXPECT_LT((q - A).norm(), 1e-12) << time;
      EXPECT_LT(qd.norm() + qdd.norm(), 1e-12) << time;
    }
  }
  // Inside the series: the coefficients as written, the offset from posture A.
  FourierTrajectory expected = series;
  expected.come_to_rest_at(A);
  for (double time = 1.5; time <= 16.5; time += 0.37) {
    t.evaluate(time, q, qd, qdd);
    expected.evaluate(std::fmod(time - 1.5, 7.5), sq, sqd, sqdd);
    EXPECT_LT((q - sq).cwiseAbs().maxCoeff(), 1e-12) << time;
    EXPECT_LT((qd - sqd).cwiseAbs().maxCoeff(), 1e-12) << time;
    EXPECT_LT((qdd - sqdd).cwiseAbs().maxCoeff(), 1e-11) << time;
  }
}

std::string failure(const std::string& text) {
  try {
    const auto d = TrajectoryDesign::read(write_temp("bad.yaml", text), joints_of<crane_x7::Model>());
    d.build("OF01");
  } catch (const DataError& e) {
    return e.what();
  }
  return "";
}

TEST(FourierInDesign, ErrorsNameTheLineAndTheJoint) {
  FourierTrajectory series = random_series(8, 3, 6, 0.05, 3);
  series.a(2, 0) += 0.01;  // joint 3 no longer at rest at t = 0
  std::string what = failure(crane_with(fourier_trajectory_yaml("OF01", "A", series, 1, "")));
  EXPECT_NE(what.find("joint 3 (upper_arm_twist) is not at rest"), std::string::npos) << what;
  EXPECT_NE(what.find("bad.yaml:"), std::string::npos) << what;
  // Too fast for joint 5's 4.8 rad/s: the build names the joint and the time.
  series = random_series(8, 3, 6, 0.05, 3);
  series.a.row(4) *= 200;
  series.b.row(4) *= 0;
  what = failure(crane_with(fourier_trajectory_yaml("OF01", "A", series, 1, "")));
  EXPECT_NE(what.find("joint 5 (lower_arm_twist)"), std::string::npos) << what;
  EXPECT_NE(what.find("at t = "), std::string::npos) << what;
  // A fourier item with a posture of its own is refused.
  std::string text = fourier_trajectory_yaml("OF01", "A", random_series(8, 3, 6, 0.05, 4), 1, "");
  text.replace(text.find("      - fourier:"), 16, "      - posture: B\n        fourier:");
  what = failure(crane_with(text));
  EXPECT_NE(what.find("takes no posture"), std::string::npos) << what;
}

}  // namespace
}  // namespace symoro::trajectory
