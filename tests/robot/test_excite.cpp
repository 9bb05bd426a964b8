// Excitation for any robot folder (compiled per robot, so also for a folder the suite has never
// seen, tools/run_tests.sh): the structured families generated from the joints build inside
// every limit, and an optimized Fourier design from the middle of the box meets every limit on a
// 0.5 ms grid, checked here with the series' own formula and the generated inverse dynamics
// with robot.yaml's nominal parameters (a 0.5 kg link per joint when it has none), and excites
// every base parameter, with a larger log det than the structured single-joint trajectory of
// the same length (and a smaller kappa where that one is poorly conditioned).
#include SYMORO_ROBOT_HEADER

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <unistd.h>

#include <gtest/gtest.h>

#include "symoro/identify/excitation_design.hpp"
#include "symoro/identify/excitation_quality.hpp"
#include "symoro/identify/identification_model.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/trajectory/structured_design.hpp"

namespace {

using Model = SYMORO_ROBOT_NS::Model;
namespace fs = std::filesystem;
using namespace symoro;

std::vector<JointInfo> joints() { return {Model::joints.begin(), Model::joints.end()}; }

bool revolute_only() {
  for (const auto& j : Model::joints)
    if (j.type != JointType::Revolute) return false;
  return true;
}

// robot.yaml's nominal, else every link a 0.5 kg point 0.1 m along its x axis (a made-up arm
// whose torques are still of a plausible size).
Eigen::Matrix<double, Model::np, 1> nominal_phi() {
  const YAML::Node nominal = YAML::LoadFile(std::string(SYMORO_ROBOT_DIR) + "/robot.yaml")["nominal"];
  Eigen::Matrix<double, Model::ns, 1> s = Eigen::Matrix<double, Model::ns, 1>::Zero();
  for (int k = 0; k < Model::ns; ++k) {
    const std::string name = Model::standard_parameters[k].name, family = Model::standard_parameters[k].family;
    if (nominal && nominal[name]) s(k) = nominal[name].as<double>();
    else if (!nominal && family == "M") s(k) = 0.5;
    else if (!nominal && family == "MX") s(k) = 0.05;
    else if (!nominal && (family == "XX" || family == "YY" || family == "ZZ")) s(k) = 0.01;
  }
  return Model::base_from_standard(s);
}

trajectory::StructuredDesignOptions structured_options() {
  trajectory::StructuredDesignOptions o;
  o.robot = Model::robot_name;
  o.joints = joints();
  return o;
}

TEST(Excite, StructuredFamiliesBuildInsideTheLimits) {
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

TEST(Excite, OptimizedDesignMeetsEveryLimitAndExcitesEveryParameter) {
  const auto model = identify::identification_model<Model>();
  const int n = Model::nq;
  identify::ExcitationDesignOptions o;
  trajectory::StructuredDesignOptions so = structured_options();
  Eigen::VectorXd lo(n), hi(n);
  if (revolute_only()) {
    trajectory::structured_box(so, lo, hi);
  } else {
    for (int j = 0; j < n; ++j) lo(j) = Model::joints[j].lower, hi(j) = Model::joints[j].upper;
  }
  o.start = (lo + hi) / 2;
  o.limits.lower = lo;
  o.limits.upper = hi;
  o.limits.velocity.resize(n);
  o.limits.torque.resize(n);
  for (int j = 0; j < n; ++j) {
    o.limits.velocity(j) = 0.5 * Model::joints[j].velocity;
    o.limits.torque(j) = Model::joints[j].effort;
  }
  o.limits.acceleration = 3.0 * o.limits.velocity;
  o.nominal = nominal_phi();
  o.harmonics = 4;
  o.period = 12;
  o.starts = 2;
  identify::ExcitationDesign d;
  try {
    d = identify::design_excitation(*model, o);
  } catch (const identify::ExcitationInfeasible& e) {
    FAIL() << "the design from the middle of the box was refused: " << e.what();
  }
  const auto& t = d.trajectory;
  Eigen::VectorXd q, qd, qdd;
  Eigen::Matrix<double, Model::nq, 1> tau;
  double worst = 1e9;
  for (double time = 0; time <= t.period(); time += 5e-4) {
    t.evaluate(time, q, qd, qdd);
    Model::inverse_dynamics(Eigen::Matrix<double, n, 1>(q), Eigen::Matrix<double, n, 1>(qd), Eigen::Matrix<double, n, 1>(qdd),
                            Eigen::Matrix<double, Model::np, 1>(o.nominal), tau);
    for (int j = 0; j < n; ++j)
      worst = std::min({worst, hi(j) - q(j), q(j) - lo(j), o.limits.velocity(j) - std::abs(qd(j)),
                        o.limits.acceleration(j) - std::abs(qdd(j)), o.limits.torque(j) - std::abs(tau(j))});
  }
  EXPECT_GE(worst, 0);
  t.evaluate(0, q, qd, qdd);
  EXPECT_LT((q - o.start).norm() + qd.norm() + qdd.norm(), 1e-12);
  const auto optimized = identify::excitation_quality(*model, t.sample(0.001), 0.01);
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
  const auto structured = identify::excitation_quality(*model, singles, 0.01);
  EXPECT_GT(optimized.log_det_scaled, structured.log_det_scaled);
  // D-optimality is not kappa: where the singles are already well conditioned (the planar 2R
  // arm: 4.5) the optimum may trade a little kappa for information; where they are poorly
  // conditioned (every arm of robots/ but the planar one), it must improve kappa too.
  if (structured.kappa_scaled > 10) EXPECT_LT(optimized.kappa_scaled, structured.kappa_scaled);
}

}  // namespace
