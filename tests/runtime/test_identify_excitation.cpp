// Optimized excitation (excitation/criterion.hpp, design.hpp) on CRANE-X7
// and the UR5: the criterion's gradient and the constraints' Jacobians against central finite
// differences; designs whose every limit holds on a dense grid, checked here with the generated
// inverse dynamics directly and the MDH frames; the gain over a structured trajectory of the
// same length; refusals that name the constraint and the joint.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include <Eigen/Core>
#include <yaml-cpp/yaml.h>

#include <symoro/crane_x7.hpp>
#include <symoro/ur5.hpp>

#include "symoro/excitation/design.hpp"
#include "symoro/excitation/quality.hpp"
#include "symoro/identify/identification_model.hpp"
#include "symoro/mdh.hpp"
#include "symoro/robot/compiled_model.hpp"
#include "symoro/trajectory/design.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/truth.hpp"

namespace {

using namespace symoro::identify;
using namespace symoro::excitation;
using Crane = symoro::crane_x7::Model;
using Ur5 = symoro::ur5::Model;

// The nominal models: CRANE-X7's CAD inertials (the twin's truth, without its hidden effects),
// the UR5's URDF inertials (robot.yaml `nominal`, in the order of the standard parameters).
Eigen::VectorXd crane_nominal() {
  const auto c = symoro::twin::read_twin_config(std::string(SYMORO_ROBOTS_DIR) + "/crane_x7/twin.yaml", Crane::nq, "");
  return symoro::twin::make_truth(symoro::robot::compiled_model<Crane>(), c).phi;
}

Eigen::VectorXd ur5_nominal() {
  const YAML::Node nominal = YAML::LoadFile(std::string(SYMORO_ROBOTS_DIR) + "/ur5/robot.yaml")["nominal"];
  Eigen::Matrix<double, Ur5::ns, 1> s;
  for (int k = 0; k < Ur5::ns; ++k) s(k) = nominal[Ur5::standard_parameters[k].name].as<double>();
  return Ur5::base_from_standard(s);
}

ExcitationDesignOptions options_for(const IdentificationModel& m, const Eigen::VectorXd& start, double margin_deg) {
  const auto& joints = m.description().joints;
  const int n = static_cast<int>(joints.size());
  ExcitationDesignOptions o;
  o.start = start;
  o.limits.lower.resize(n);
  o.limits.upper.resize(n);
  o.limits.velocity.resize(n);
  o.limits.acceleration.resize(n);
  o.limits.torque.resize(n);
  const double margin = margin_deg * M_PI / 180;
  for (int j = 0; j < n; ++j) {
    // At most 60 deg either side of the start: an arm's +-2 pi joints swing within reason.
    o.limits.lower(j) = std::max(joints[j].lower + margin, start(j) - M_PI / 3);
    o.limits.upper(j) = std::min(joints[j].upper - margin, start(j) + M_PI / 3);
    o.limits.velocity(j) = 0.5 * joints[j].velocity;
    o.limits.acceleration(j) = 2.0 * joints[j].velocity;
    o.limits.torque(j) = joints[j].effort;
  }
  return o;
}

Eigen::VectorXd random_coefficients(const FourierBasis& b, const Eigen::VectorXd& start, double size, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g;
  symoro::trajectory::FourierTrajectory t;
  t.w = b.pulsation();
  t.a.resize(b.joints(), b.harmonics());
  t.b.resize(b.joints(), b.harmonics());
  for (int j = 0; j < b.joints(); ++j)
    for (int l = 0; l < b.harmonics(); ++l) {
      t.a(j, l) = size * g(rng);
      t.b(j, l) = size * g(rng);
    }
  t.come_to_rest_at(start);
  return b.coefficients(t);
}

// d f / dx against central differences, coefficient by coefficient.
void expect_gradient_matches(const IdentificationModel& m, const Eigen::VectorXd& start, unsigned seed) {
  ExcitationCriterion c(m, FourierBasis(m.description().nq, 3, 8.0, 48, start));
  const Eigen::VectorXd x = random_coefficients(c.basis(), start, 0.4, seed);
  c.scale_columns_at(x);
  Eigen::VectorXd grad;
  ASSERT_TRUE(c.value(x, &grad).has_value());
  double worst = 0;
  for (int i = 0; i < x.size(); ++i) {
    const double h = 1e-6;
    Eigen::VectorXd xp = x, xm = x;
    xp(i) += h;
    xm(i) -= h;
    const double fd = (*c.value(xp) - *c.value(xm)) / (2 * h);
    worst = std::max(worst, std::abs(fd - grad(i)) / std::max(1.0, std::abs(grad(i))));
  }
  EXPECT_LT(worst, 2e-5) << m.description().robot;
  EXPECT_GT(grad.norm(), 1.0);  // a gradient that is not trivially zero
}

TEST(ExcitationCriterion, GradientMatchesFiniteDifferences) {
  expect_gradient_matches(*identification_model<Crane>(), Eigen::VectorXd::Zero(Crane::nq).eval(), 3);
  Eigen::VectorXd ur5_start(6);
  ur5_start << 0, -1.2, 1.2, -1.5, -1.5, 0;
  expect_gradient_matches(*identification_model<Ur5>(), ur5_start, 4);
}

TEST(ExcitationCriterion, TorqueAndWorkspaceJacobiansMatchFiniteDifferences) {
  const auto m = identification_model<Ur5>();
  Eigen::VectorXd start(6);
  start << 0.3, -1.2, 1.2, -1.5, -1.5, 0.2;
  ExcitationCriterion c(*m, FourierBasis(6, 3, 6.0, 24, start));
  const Eigen::VectorXd x = random_coefficients(c.basis(), start, 0.5, 9);
  const Eigen::VectorXd phi = ur5_nominal();
  std::vector<HalfSpace> spaces{{"table", 6, Eigen::Vector3d(0, 0, -1), 0.1},
                                {"wall", 4, Eigen::Vector3d(1, 0.5, 0).normalized(), 0.4}};
  Eigen::MatrixXd Jt, Jw;
  c.torque(x, phi, &Jt);
  c.workspace(x, spaces, &Jw);
  const double h = 1e-6;
  double worst_t = 0, worst_w = 0;
  for (int i = 0; i < x.size(); ++i) {
    Eigen::VectorXd xp = x, xm = x;
    xp(i) += h;
    xm(i) -= h;
    const Eigen::MatrixXd dt = (c.torque(xp, phi) - c.torque(xm, phi)) / (2 * h);
    const Eigen::MatrixXd dw = (c.workspace(xp, spaces) - c.workspace(xm, spaces)) / (2 * h);
    for (int k = 0; k < dt.rows(); ++k) {
      for (int j = 0; j < 6; ++j) worst_t = std::max(worst_t, std::abs(dt(k, j) - Jt(k * 6 + j, i)));
      for (int s = 0; s < 2; ++s) worst_w = std::max(worst_w, std::abs(dw(k, s) - Jw(k * 2 + s, i)));
    }
  }
  EXPECT_LT(worst_t, 1e-5 * std::max(1.0, Jt.cwiseAbs().maxCoeff()));
  EXPECT_LT(worst_w, 1e-8);
  EXPECT_GT(Jw.cwiseAbs().maxCoeff(), 0.01);
}

// Every limit on a 0.5 ms grid (twice as dense as the design's check), evaluated here: the
// series by its own formula, the torque by the generated inverse dynamics, the frames by MDH.
template <class Model>
void expect_limits_hold(const ExcitationDesign& d, const ExcitationDesignOptions& o, const Eigen::VectorXd& phi) {
  const auto& t = d.trajectory;
  const int n = Model::nq;
  Eigen::VectorXd q, qd, qdd;
  t.evaluate(0, q, qd, qdd);
  EXPECT_LT((q - o.start).norm(), 1e-12);
  EXPECT_LT(qd.norm() + qdd.norm(), 1e-12);
  t.evaluate(t.period(), q, qd, qdd);
  EXPECT_LT((q - o.start).norm(), 1e-9);
  EXPECT_LT(qd.norm() + qdd.norm(), 1e-9);
  const std::vector<symoro::FrameInfo> frames(Model::frames.begin(), Model::frames.end());
  double worst_q = 1e9, worst_qd = 1e9, worst_qdd = 1e9, worst_tau = 1e9, worst_ws = 1e9, moved = 0;
  Eigen::Matrix<double, n, 1> tau;
  for (double time = 0; time <= t.period(); time += 5e-4) {
    t.evaluate(time, q, qd, qdd);
    Model::inverse_dynamics(Eigen::Matrix<double, n, 1>(q), Eigen::Matrix<double, n, 1>(qd),
                            Eigen::Matrix<double, n, 1>(qdd), Eigen::Matrix<double, Model::np, 1>(phi), tau);
    for (int j = 0; j < n; ++j) {
      worst_q = std::min({worst_q, o.limits.upper(j) - q(j), q(j) - o.limits.lower(j)});
      worst_qd = std::min(worst_qd, o.limits.velocity(j) - std::abs(qd(j)));
      worst_qdd = std::min(worst_qdd, o.limits.acceleration(j) - std::abs(qdd(j)));
      worst_tau = std::min(worst_tau, o.limits.torque(j) - std::abs(tau(j)));
      moved = std::max(moved, std::abs(q(j) - o.start(j)));
    }
    const auto T = symoro::mdh_poses(frames, q);
    for (const auto& s : o.workspace)
      worst_ws = std::min(worst_ws, s.offset - s.normal.dot(T[s.frame - 1].translation()));
  }
  EXPECT_GE(worst_q, 0);
  EXPECT_GE(worst_qd, 0);
  EXPECT_GE(worst_qdd, 0);
  EXPECT_GE(worst_tau, 0);
  EXPECT_GE(worst_ws, 0);
  // ... and the design uses its room: some limit is nearly reached, the arm moves.
  EXPECT_LT(std::min({worst_q, worst_qd, worst_qdd, worst_tau}), 0.05);
  EXPECT_GT(moved, 0.2);
}

TEST(ExcitationDesign, UR5DesignMeetsEveryLimitOnADenseGrid) {
  const auto m = identification_model<Ur5>();
  Eigen::VectorXd start(6);
  start << 0, -1.3, 1.3, -1.5, -1.5, 0;
  ExcitationDesignOptions o = options_for(*m, start, 2);
  o.period = 8;
  o.harmonics = 4;
  o.starts = 2;
  o.nominal = ur5_nominal();
  o.limits.torque(1) = 60;  // the shoulder held near its gravity load: the torque limit binds
  // A table 0.1 m below the base for the wrist frames.
  for (int f : {4, 5, 6}) o.workspace.push_back({"table@" + std::to_string(f), f, Eigen::Vector3d(0, 0, -1), 0.1});
  const ExcitationDesign d = design_excitation(*m, o);
  ASSERT_GE(d.chosen, 0);
  expect_limits_hold<Ur5>(d, o, o.nominal);
  for (const auto& s : d.slack) EXPECT_GE(s.slack, 0) << s.constraint << " " << s.where;
}

TEST(ExcitationDesign, CraneDesignMeetsEveryLimitAndBeatsAStructuredTrajectory) {
  const auto m = identification_model<Crane>();
  Eigen::VectorXd start = Eigen::VectorXd::Zero(8);
  start(3) = -M_PI / 2;  // posture A
  start(7) = 0.7;
  ExcitationDesignOptions o = options_for(*m, start, 2);
  o.nominal = crane_nominal();
  // PA01, posture A's single-joint primitives at the low speed level: a well-made but
  // structured trajectory, poorly conditioned on its own (every joint moves alone, in one
  // posture). The optimized series of the same length, under the same velocity limits as the
  // design file's speed level 1 (0.25-0.3 of the file's limits) and twice its acceleration.
  const auto design = symoro::trajectory::TrajectoryDesign::read(
      std::string(SYMORO_ROBOTS_DIR) + "/crane_x7/trajectories.yaml", m->description().joints);
  const auto pa01 = design.build("PA01");
  o.period = pa01.duration();
  o.harmonics = 5;
  o.starts = 2;
  o.limits.velocity = Eigen::VectorXd::Constant(8, 0.6);
  o.limits.acceleration = Eigen::VectorXd::Constant(8, 3.0);
  const ExcitationDesign d = design_excitation(*m, o);
  expect_limits_hold<Crane>(d, o, o.nominal);
  const auto structured = excitation_quality(*m, symoro::trajectory::sample(pa01, 0.001), 0.01);
  const auto optimized = excitation_quality(*m, d.trajectory.sample(0.001), 0.01);
  // Unit columns: both measure how well the motion tells the parameters apart.
  EXPECT_GT(optimized.log_det_scaled, structured.log_det_scaled + 10) << structured.log_det_scaled;
  EXPECT_LT(optimized.kappa_scaled, structured.kappa_scaled / 2) << structured.kappa_scaled;
  EXPECT_LT(optimized.kappa, structured.kappa) << structured.kappa;
}

TEST(ExcitationDesign, UnmeetableLimitsAreRefusedWithConstraintAndJoint) {
  const auto m = identification_model<Ur5>();
  Eigen::VectorXd start(6);
  start << 0, -1.3, 1.3, -1.5, -1.5, 0;
  auto refused = [&](const ExcitationDesignOptions& o) -> std::string {
    try {
      design_excitation(*m, o);
    } catch (const ExcitationInfeasible& e) {
      return e.what();
    }
    return "";
  };
  ExcitationDesignOptions o = options_for(*m, start, 2);
  o.nominal = ur5_nominal();
  o.limits.torque(1) = 20;  // less than the shoulder's gravity load at the start
  std::string what = refused(o);
  EXPECT_NE(what.find("torque limit of joint 2 (shoulder_lift_joint)"), std::string::npos) << what;
  o = options_for(*m, start, 2);
  o.nominal = ur5_nominal();
  o.limits.upper(2) = 1.0;  // the elbow starts beyond its limit
  what = refused(o);
  EXPECT_NE(what.find("position limit of joint 3 (elbow_joint)"), std::string::npos) << what;
  o = options_for(*m, start, 2);
  o.nominal = ur5_nominal();
  o.limits.acceleration(4) = 0;
  what = refused(o);
  EXPECT_NE(what.find("acceleration limit of joint 5 (wrist_2_joint)"), std::string::npos) << what;
  o = options_for(*m, start, 2);
  o.nominal = ur5_nominal();
  o.workspace.push_back({"floor", 6, Eigen::Vector3d(0, 0, -1), -2.0});  // the start is below it
  what = refused(o);
  EXPECT_NE(what.find("workspace half-space floor"), std::string::npos) << what;
}

}  // namespace
