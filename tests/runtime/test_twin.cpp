// The digital twin: its truth (CAD inertials mapped into the model's frames) against FACTS.md's
// hand checks and against an independent computation in the URDF frames (kinetic energy and
// gravity torques), energy conservation of the plant, integration accuracy, and the closed
// loop's tracking error against the bound derived in tracking_bound.hpp.
#include <cmath>
#include <fstream>
#include <iostream>
#include <random>

#include <gtest/gtest.h>

#include <symoro/crane_x7.hpp>

#include "symoro/robot/compiled_model.hpp"
#include "symoro/twin/config.hpp"
#include "symoro/twin/kinematics.hpp"
#include "symoro/twin/plant.hpp"
#include "symoro/twin/truth.hpp"

namespace {

using Model = symoro::crane_x7::Model;
using namespace symoro::twin;
constexpr int n = Model::nq;
using JointVec = Eigen::Matrix<double, n, 1>;
const std::string kTwin = std::string(SYMORO_ROBOTS_DIR) + "/crane_x7/twin.yaml";

TwinConfig config() { return read_twin_config(kTwin, n); }

double phi_of(const Eigen::VectorXd& phi, const std::string& name) {
  for (int i = 0; i < Model::np; ++i)
    if (name == Model::parameters[i].name) return phi(i);
  ADD_FAILURE() << "no parameter " << name;
  return 0;
}

// Body velocities and positions straight from the URDF chain: joint axes and origins in the
// URDF base, each body's CoM, rotation and inertia (no model frames involved).
struct UrdfBodies {
  std::vector<Eigen::Vector3d> com;      // in the URDF base
  std::vector<Eigen::Matrix3d> inertia;  // about the CoM, base axes
  std::vector<Eigen::MatrixXd> jv, jw;   // 3 x n CoM linear and angular Jacobians
  std::vector<double> mass;
};

UrdfBodies urdf_bodies(const TwinConfig& c, const Eigen::VectorXd& q) {
  const auto T = urdf_poses(c.chain, q);
  UrdfBodies b;
  for (const auto& in : c.chain.inertials) {
    int i = 0;
    while (c.chain.joints[i].name != in.on) ++i;
    const Eigen::Vector3d p = T[i] * (in.origin + in.com);
    const Eigen::Matrix3d R = T[i].linear() * rotation_from_rpy(in.rpy);
    Eigen::MatrixXd jv = Eigen::MatrixXd::Zero(3, n), jw = Eigen::MatrixXd::Zero(3, n);
    for (int k = 0; k <= i; ++k) {
      const auto& j = c.chain.joints[k];
      if (j.fixed) continue;
      const Eigen::Vector3d a = T[k].linear() * j.axis, o = T[k].translation();
      jw.col(j.model_joint - 1) = a;
      jv.col(j.model_joint - 1) = a.cross(p - o);
    }
    b.com.push_back(p);
    b.inertia.push_back(R * in.inertia * R.transpose());
    b.jv.push_back(jv);
    b.jw.push_back(jw);
    b.mass.push_back(in.mass);
  }
  return b;
}

TEST(TwinTruth, FactsHandChecks) {
  const auto truth = make_truth(symoro::robot::compiled_model<Model>(), config());
  // FACTS.md: MYR2 about -0.236 kg m, MYR4 about -0.129 kg m with the URDF values.
  EXPECT_NEAR(phi_of(truth.phi, "MYR2"), -0.236, 0.002);
  EXPECT_NEAR(phi_of(truth.phi, "MYR4"), -0.129, 0.002);
  // The grouping itself, by hand: MYR2 = -L3 MR3 + MY2 - MZ3 with MR3 the mass from link 3 on.
  double mr3 = 0;
  for (int j = 2; j < 7; ++j) mr3 += truth.links[j].m;
  EXPECT_NEAR(phi_of(truth.phi, "MYR2"), -0.25 * mr3 + truth.links[1].ms.y() - truth.links[2].ms.z(), 1e-12);
  EXPECT_NEAR(mr3, 0.321 + 0.222 + 0.207 + 0.14 + 0.121 + 0.0158 + 0.0139, 1e-12);
  // The paper's order of magnitude for the folded rotor inertias (Appendix A).
  EXPECT_NEAR(phi_of(truth.phi, "ZZR1"), 0.01184, 0.001) << phi_of(truth.phi, "ZZR1");
  EXPECT_NEAR(phi_of(truth.phi, "ZZR2"), 0.0904, 0.002) << phi_of(truth.phi, "ZZR2");
}

TEST(TwinTruth, KineticEnergyMatchesUrdfFrames) {
  const TwinConfig c = config();
  const auto truth = make_truth(symoro::robot::compiled_model<Model>(), c);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::VectorXd q(n), qd(n);
    for (int j = 0; j < n; ++j) q(j) = u(rng), qd(j) = u(rng);
    const UrdfBodies b = urdf_bodies(c, q);
    double ke = 0.5 * (c.rotor_inertia.array() * qd.array().square()).sum();
    for (size_t i = 0; i < b.mass.size(); ++i) {
      const Eigen::Vector3d v = b.jv[i] * qd, w = b.jw[i] * qd;
      ke += 0.5 * b.mass[i] * v.squaredNorm() + 0.5 * w.dot(b.inertia[i] * w);
    }
    Eigen::Matrix<double, n, n> M;
    Model::inertia(q, truth.phi, M);
    EXPECT_NEAR(0.5 * qd.dot(M * qd), ke, 1e-12 + 1e-10 * ke) << "trial " << trial;
  }
}

TEST(TwinTruth, GravityTorqueMatchesUrdfFrames) {
  const TwinConfig c = config();
  const auto truth = make_truth(symoro::robot::compiled_model<Model>(), c);
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  const Eigen::Vector3d g(0, 0, -9.80665);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::VectorXd q(n);
    for (int j = 0; j < n; ++j) q(j) = u(rng);
    const UrdfBodies b = urdf_bodies(c, q);
    // Holding torque = - J^T (m g) summed over bodies.
    Eigen::VectorXd expected = Eigen::VectorXd::Zero(n);
    for (size_t i = 0; i < b.mass.size(); ++i) expected -= b.jv[i].transpose() * (b.mass[i] * g);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
    Eigen::Matrix<double, n, 1> tau;
    Model::inverse_dynamics(q, zero, zero, truth.phi, tau);
    EXPECT_LT((tau - expected).cwiseAbs().maxCoeff(), 1e-12) << "trial " << trial;
  }
}

TEST(TwinTruth, RejectsAMismatchedChain) {
  TwinConfig c = config();
  c.chain.base_in_urdf.linear().setIdentity();  // x forward: joint 2 would turn the other way
  try {
    make_truth(symoro::robot::compiled_model<Model>(), c);
    FAIL() << "a wrong base_in_urdf was accepted";
  } catch (const symoro::DataError& e) {
    EXPECT_NE(std::string(e.what()).find("does not move with model frame"), std::string::npos) << e.what();
  }
  c = config();
  c.chain.joints[2].axis = -c.chain.joints[2].axis;  // shoulder_tilt reversed
  EXPECT_THROW(make_truth(symoro::robot::compiled_model<Model>(), c), symoro::DataError);
}

TEST(TwinConfigFile, ErrorsNameFileAndLine) {
  const auto dir = std::filesystem::temp_directory_path() / "symoro_twin_config_test";
  std::filesystem::create_directories(dir);
  const auto over = dir / "over.yaml";
  std::ofstream(over) << "effects:\n  coulomb:\n    enabled: true\n    torque: [0.1, 0.1]\n";
  try {
    read_twin_config(kTwin, n, over);
    FAIL();
  } catch (const symoro::DataError& e) {
    EXPECT_EQ(e.file(), over.string());
    EXPECT_EQ(e.line(), 4);
    EXPECT_NE(std::string(e.what()).find("expected 8"), std::string::npos) << e.what();
  }
  std::ofstream(over) << "effects:\n  coulomb:\n    enabled: true\n";
  const TwinConfig c = read_twin_config(kTwin, n, over);
  EXPECT_TRUE(c.effects.coulomb);
  EXPECT_NEAR(c.effects.coulomb_torque(1), 0.08, 0);  // kept from twin.yaml
  std::ofstream(over) << "effects:\n  colomb: {enabled: true}\n";
  try {
    read_twin_config(kTwin, n, over);
    FAIL();
  } catch (const symoro::DataError& e) {
    EXPECT_EQ(e.line(), 2);
    EXPECT_NE(std::string(e.what()).find("unknown key 'colomb'"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

// Potential energy straight from the URDF chain: U = -sum m g . p_com.
double potential(const TwinConfig& c, const Eigen::VectorXd& q) {
  const UrdfBodies b = urdf_bodies(c, q);
  double U = 0;
  for (size_t i = 0; i < b.mass.size(); ++i) U += b.mass[i] * 9.80665 * b.com[i].z();
  return U;
}

TEST(TwinPlant, ConservesEnergyWithoutFrictionAndControl) {
  TwinConfig c = config();
  c.effects.disable_all();
  c.viscous.setZero();
  const auto truth = make_truth(symoro::robot::compiled_model<Model>(), c);
  JointVec q0;
  q0 << 0.3, 0.8, -0.4, -1.2, 0.5, 0.7, -0.3, 0.2;
  Plant plant(symoro::robot::compiled_model<Model>(), truth, c, q0);
  const auto energy = [&] { return plant.kinetic_energy() + potential(c, plant.q()); };
  const double e0 = energy();
  double swing = 0, drift = 0;
  for (int k = 0; k < 2000; ++k) {  // 2 s of free fall and swinging
    plant.advance(0.001, JointVec::Zero());
    swing = std::max(swing, plant.kinetic_energy());
    drift = std::max(drift, std::abs(energy() - e0));
  }
  EXPECT_GT(swing, 0.5);  // the arm really moved (J of kinetic energy)
  // RK4 at the configured 1 ms step: measured 4e-9 of the kinetic energy scale after 2 s.
  EXPECT_LT(drift, 1e-8 * swing);
}

TEST(TwinPlant, StepIsConvergedFarBelowTheEncoderResolution) {
  TwinConfig c = config();
  c.effects.disable_all();
  c.effects.coulomb = true;  // the stiffest smooth term of the rigid plant
  const auto truth = make_truth(symoro::robot::compiled_model<Model>(), c);
  JointVec q0, tau;
  q0 << 0.3, 0.8, -0.4, -1.2, 0.5, 0.7, -0.3, 0.2;
  tau << 0.2, 1.0, 0.1, 0.5, 0.05, 0.05, 0.02, 0.01;
  Plant coarse(symoro::robot::compiled_model<Model>(), truth, c, q0);
  TwinConfig fine_c = c;
  fine_c.max_step = c.max_step / 16;
  Plant fine(symoro::robot::compiled_model<Model>(), truth, fine_c, q0);
  double worst = 0;
  for (int k = 0; k < 1000; ++k) {
    const JointVec t = tau * std::sin(0.01 * k);  // a held, changing command
    coarse.advance(0.0009, t), fine.advance(0.0009, t);
    coarse.advance(0.0001, t), fine.advance(0.0001, t);
    worst = std::max(worst, (coarse.q() - fine.q()).cwiseAbs().maxCoeff());
  }
  const double lsb = 2 * M_PI / 4096;
  EXPECT_LT(worst, 1e-3 * lsb) << "max |q_coarse - q_fine| = " << worst;
  RecordProperty("step_error_rad", std::to_string(worst));
}

}  // namespace

namespace {

// The controller's realization inertias (twin.yaml) play the role of a joint-level fit: they
// must be near the true diagonal inertia at posture A, where the paper fitted them.
TEST(TwinConfigFile, RealizationInertiaIsTheDiagonalAtPostureA) {
  const TwinConfig c = config();
  const auto truth = make_truth(symoro::robot::compiled_model<Model>(), c);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(n);
  q(3) = -M_PI / 2;
  Eigen::Matrix<double, n, n> M;
  Model::inertia(q, truth.phi, M);
  for (int j = 0; j < n; ++j)
    EXPECT_NEAR(c.controller.realization_inertia(j), M(j, j), 0.1 * M(j, j)) << "joint " << j + 1;
}

}  // namespace

#include "symoro/trajectory/design.hpp"
#include "symoro/twin/simulator.hpp"
#include "symoro/twin/tracking_bound.hpp"

namespace {

// For a critically damped continuous loop without delay the torque gain is exactly 1/(m K_P)
// (the impulse response t e^{-wt}/m is positive): the sampled loop with delay must be close.
TEST(TwinTracking, LoopGainMatchesTheContinuousLimit) {
  TwinConfig c = config();
  for (int j = 0; j < n; ++j) {
    const double m = c.controller.realization_inertia(j), w = c.controller.bandwidth(j);
    const LoopGains g = loop_gains(c, j);
    EXPECT_NEAR(g.torque, 1 / (m * w * w), 0.15 / (m * w * w)) << "joint " << j + 1;
    EXPECT_GT(g.measurement, 0.9);  // a measurement error passes at least once to q
  }
}

TEST(TwinTracking, ErrorStaysWithinTheDerivedBound) {
  const TwinConfig c = config();  // default effects: noise, jitter, dropped samples
  const ClosedLoopTwin twin(symoro::robot::compiled_model<Model>(), c);
  const auto design = symoro::trajectory::TrajectoryDesign::read(
      std::string(SYMORO_ROBOTS_DIR) + "/crane_x7/trajectories.yaml",
      std::vector<symoro::JointInfo>(Model::joints.begin(), Model::joints.end()));
  for (const std::string name : {"PA03", "PC06", "AP01", "V01"}) {
    const auto traj = design.build(name);
    const auto needed = [&](const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd) {
      Eigen::Matrix<double, n, 1> tau;
      Model::inverse_dynamics(q, qd, qdd, twin.truth().phi, tau);
      return Eigen::VectorXd(tau);
    };
    const Eigen::VectorXd bound = tracking_error_bound(c, unmodeled_torque(c, traj, needed));
    RunOptions ro;
    ro.seed = 11;
    RunStats st;
    twin.run(traj, ro, &st);
    for (int j = 0; j < n; ++j) {
      EXPECT_LE(st.max_error(j), bound(j)) << name << " joint " << j + 1;
      // The bound is informative: within a few times the observed error and under 5 deg.
      EXPECT_LT(bound(j), 5 * M_PI / 180) << name << " joint " << j + 1;
    }
    std::cout << name << " max error / bound (deg):";
    for (int j = 0; j < n; ++j) std::cout << " " << st.max_error(j) * 180 / M_PI << "/" << bound(j) * 180 / M_PI;
    std::cout << "\n";
  }
}

}  // namespace

namespace {

JointVec posture_a() {
  JointVec q = JointVec::Zero();
  q(3) = -M_PI / 2;
  return q;
}

TEST(TwinEffects, BacklashIsResolvedAndHoldsTheLinkAgainstTheGear) {
  TwinConfig c = config();
  c.effects.disable_all();
  c.effects.backlash = true;
  // Play on joint 2 only, which gravity keeps loaded: the gear stays in mesh and the motion is
  // smooth, so step convergence is measurable. (With play everywhere and feedback, the wrist
  // hunts inside its play: a chaotic, physical limit cycle that no step size "converges".)
  const double width = c.effects.backlash_width(1);
  c.effects.backlash_width.setZero();
  c.effects.backlash_width(1) = width;
  const auto truth = make_truth(symoro::robot::compiled_model<Model>(), c);
  Plant plant(symoro::robot::compiled_model<Model>(), truth, c, posture_a());
  EXPECT_LE(plant.max_step(), 0.3 / (2 * M_PI * c.effects.backlash_frequency) + 1e-15);
  // Under the FF+PD controller (stable, unlike an open-loop hold), swinging joint 2 by 0.2 rad
  // and back: the step the plant chose is converged (1/8 of it agrees to a fraction of a count).
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  JointVec g;
  Model::inverse_dynamics(posture_a(), zero, zero, truth.phi, g);
  TwinConfig fine_c = c;
  fine_c.max_step = plant.max_step() / 8;
  Plant fine(symoro::robot::compiled_model<Model>(), truth, fine_c, posture_a());
  symoro::control::FfpdController ca(controller_gains(c)), cb(controller_gains(c));
  ca.reset(posture_a()), cb.reset(posture_a());
  double worst = 0;
  for (int k = 0; k < 2000; ++k) {
    Eigen::VectorXd ref = posture_a();
    ref(1) += 0.2 * std::sin(M_PI * k / 1000.0);
    const JointVec ua = ca.update(plant.q(), ref, zero, zero), ub = cb.update(fine.q(), ref, zero, zero);
    plant.advance(0.001, ua), fine.advance(0.001, ub);
    worst = std::max(worst, (plant.q() - fine.q()).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 0.05 * 2 * M_PI / 4096) << "step error " << worst;
  // Settled at posture A again: hold there and look at the gear.
  for (int k = 0; k < 500; ++k) plant.advance(0.001, ca.update(plant.q(), posture_a(), zero, zero));
  // Joint 2 carries a large gravity torque: its rotor leads the link by half the play plus the
  // mesh deflection, on the side that holds the arm up.
  const double half = c.effects.backlash_width(1) / 2;
  const double lead = plant.rotor_q()(1) - plant.q()(1);
  EXPECT_GT(std::abs(lead), half);
  EXPECT_LT(std::abs(lead), half + 0.01);
  EXPECT_EQ(lead > 0, g(1) > 0);
}

TEST(TwinEffects, PayloadAddsItsWeightToTheGravityTorques) {
  TwinConfig c = config();
  c.effects.disable_all();
  const auto plain = make_truth(symoro::robot::compiled_model<Model>(), c);
  c.effects.payload = true;
  const auto loaded = make_truth(symoro::robot::compiled_model<Model>(), c);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd q = posture_a();
  q(1) = 0.4, q(5) = 0.3;
  JointVec t0, t1;
  Model::inverse_dynamics(q, zero, zero, plain.phi, t0);
  Model::inverse_dynamics(q, zero, zero, loaded.phi, t1);
  // The payload's weight m g acting at its position p: holding torques a_j x (p - o_j) . (m g e_z).
  const auto T = mdh_poses(symoro::robot::compiled_model<Model>().frames(), q);
  const Eigen::Vector3d p = T[6] * c.effects.payload_com;
  for (int j = 0; j < n; ++j) {
    const Eigen::Vector3d a = T[j].linear().col(2), o = T[j].translation();
    const double expected = j < 7 ? a.cross(p - o).dot(Eigen::Vector3d(0, 0, c.effects.payload_mass * 9.80665)) : 0.0;
    EXPECT_NEAR(t1(j) - t0(j), expected, 1e-12) << "joint " << j + 1;
  }
}

TEST(TwinRun, LogHasTheServosResolutionAndIsReproducible) {
  const TwinConfig c = config();
  const ClosedLoopTwin twin(symoro::robot::compiled_model<Model>(), c);
  const auto design = symoro::trajectory::TrajectoryDesign::read(
      std::string(SYMORO_ROBOTS_DIR) + "/crane_x7/trajectories.yaml",
      std::vector<symoro::JointInfo>(Model::joints.begin(), Model::joints.end()));
  const auto traj = design.build("V02");
  RunOptions ro;
  ro.seed = 5;
  RunStats st;
  const auto log = twin.run(traj, ro, &st);
  // Every cycle but the dropped ones is logged, at stamps within the jitter of k T.
  EXPECT_EQ(log.samples() + st.dropped, st.cycles);
  EXPECT_GT(st.dropped, 0);
  const double lsb = 2 * M_PI / 4096;
  for (int k = 0; k < log.samples(); ++k) {
    const double cycle = std::round(log.time(k) / 0.001);
    ASSERT_LE(std::abs(log.time(k) - cycle * 0.001), c.effects.jitter_max + 1e-12);
    if (k > 0) ASSERT_GT(log.time(k), log.time(k - 1));
    for (int j = 0; j < n; ++j) {
      // Encoder counts and current steps: q on the 12-bit grid, tau on the Kt x 2.69 mA grid.
      ASSERT_NEAR(log.q(k, j) / lsb, std::round(log.q(k, j) / lsb), 1e-6);
      const double step = c.servos[j].torque_constant * c.servos[j].current_unit;
      ASSERT_NEAR(log.tau(k, j) / step, std::round(log.tau(k, j) / step), 1e-6);
    }
  }
  const auto again = twin.run(traj, ro);
  EXPECT_EQ(again.tau, log.tau);
  EXPECT_EQ(again.time, log.time);
  ro.seed = 6;
  const auto other = twin.run(traj, ro);
  EXPECT_NE(other.time.size() == log.time.size() ? (other.tau - log.tau).norm() : 1.0, 0.0);
}

// The logged torque is the current the servos held when the row was stamped: the command of
// the previous cycle (applied d after its measurement). A step in the reference shows in the
// logged torque one cycle later.
TEST(TwinRun, CommandReachesTheLogOneCycleLater) {
  TwinConfig c = config();
  c.effects.disable_all();
  // A fine encoder: no count hunting at rest, so only the timing shows.
  for (auto& s : c.servos) s.encoder_counts = 1 << 30;
  const ClosedLoopTwin twin(symoro::robot::compiled_model<Model>(), c);
  symoro::trajectory::Trajectory step;
  step.name = "step";
  symoro::trajectory::Segment hold;
  hold.from = hold.to = posture_a();
  hold.profile.duration = 0.01;
  step.segments.push_back(hold);
  symoro::trajectory::Segment jump = hold;
  jump.start = 0.01;
  jump.from = jump.to = posture_a() + Eigen::VectorXd::Constant(n, 0.01);
  step.segments.push_back(jump);
  RunOptions ro;
  ro.pre_roll = 1.0;
  const auto log = twin.run(step, ro);
  const int k = 10;  // the reference jumps at cycle 10
  for (int j = 0; j < n; ++j) {
    EXPECT_NEAR(log.tau(k, j), log.tau(k - 1, j), 0.01) << "joint " << j + 1;
    // One cycle later the P term m K_P 0.01 has arrived.
    const double kick = c.controller.realization_inertia(j) * std::pow(c.controller.bandwidth(j), 2) * 0.01;
    EXPECT_GT(log.tau(k + 1, j) - log.tau(k, j), 0.5 * kick) << "joint " << j + 1;
  }
}

// The actuation delay shifts the torque the plant receives, not what the log reports: with a
// delay of exactly three periods the link answers a reference step three cycles later, along
// the same path at first (before the feedback of the late motion differs). Each run's step
// response is taken against the same run without the step (the held arm still settles).
TEST(TwinEffects, ActuationDelayShiftsTheTorqueTheLinkReceives) {
  TwinConfig c = config();
  c.effects.disable_all();
  for (auto& s : c.servos) s.encoder_counts = 1 << 30;
  auto reference = [&](double size) {
    symoro::trajectory::Trajectory t;
    t.name = "step";
    symoro::trajectory::Segment hold;
    hold.from = hold.to = posture_a();
    hold.profile.duration = 0.01;
    t.segments.push_back(hold);
    symoro::trajectory::Segment jump = hold;
    jump.start = 0.01;
    jump.from = jump.to = posture_a() + Eigen::VectorXd::Constant(n, size);
    t.segments.push_back(jump);
    return t;
  };
  RunOptions ro;
  ro.pre_roll = 1.0;
  auto response = [&](const TwinConfig& cfg) {
    const ClosedLoopTwin twin(symoro::robot::compiled_model<Model>(), cfg);
    return Eigen::MatrixXd(twin.run(reference(0.01), ro).q - twin.run(reference(0.0), ro).q);
  };
  const Eigen::MatrixXd base = response(c);
  c.effects.actuation_delay = true;
  c.effects.actuation_delay_time = 3 * c.controller.period;
  const Eigen::MatrixXd late = response(c);
  const int k = 10;  // the reference steps at cycle 10
  for (int j = 0; j < n; ++j) {
    EXPECT_GT(std::abs(base(k + 3, j)), 1e-7) << "joint " << j + 1;
    EXPECT_LT(std::abs(late(k + 3, j)), 1e-3 * std::abs(base(k + 3, j))) << "joint " << j + 1;
    for (int i = 2; i <= 3; ++i)
      EXPECT_NEAR(late(k + i + 3, j), base(k + i, j), 0.25 * std::abs(base(k + i, j)))
          << "joint " << j + 1 << " row " << k + i;
  }
}
}  // namespace
