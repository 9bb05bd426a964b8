// The digital twin: its truth (CAD inertials mapped into the model's frames) against FACTS.md's
// hand checks and against an independent computation in the URDF frames (kinetic energy and
// gravity torques), energy conservation of the plant, integration accuracy, and the closed
// loop's tracking error against the bound derived in tracking_bound.hpp.
#include <cmath>
#include <fstream>
#include <random>

#include <gtest/gtest.h>

#include <symoro/crane_x7.hpp>

#include "symoro/twin/config.hpp"
#include "symoro/twin/kinematics.hpp"
#include "symoro/twin/plant.hpp"
#include "symoro/twin/truth.hpp"

namespace {

using Model = symoro::crane_x7::Model;
using namespace symoro::twin;
constexpr int n = Model::nq;
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
  const auto truth = make_truth<Model>(config());
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
  const auto truth = make_truth<Model>(c);
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
  const auto truth = make_truth<Model>(c);
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
    make_truth<Model>(c);
    FAIL() << "a wrong base_in_urdf was accepted";
  } catch (const symoro::DataError& e) {
    EXPECT_NE(std::string(e.what()).find("does not move with model frame"), std::string::npos) << e.what();
  }
  c = config();
  c.chain.joints[2].axis = -c.chain.joints[2].axis;  // shoulder_tilt reversed
  EXPECT_THROW(make_truth<Model>(c), symoro::DataError);
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
  const auto truth = make_truth<Model>(c);
  Plant<Model>::Vec q0;
  q0 << 0.3, 0.8, -0.4, -1.2, 0.5, 0.7, -0.3, 0.2;
  Plant<Model> plant(truth, c, q0);
  const auto energy = [&] { return plant.kinetic_energy() + potential(c, plant.q()); };
  const double e0 = energy();
  double swing = 0, drift = 0;
  for (int k = 0; k < 2000; ++k) {  // 2 s of free fall and swinging
    plant.advance(0.001, Plant<Model>::Vec::Zero());
    swing = std::max(swing, plant.kinetic_energy());
    drift = std::max(drift, std::abs(energy() - e0));
  }
  EXPECT_GT(swing, 0.5);           // the arm really moved (J of kinetic energy)
  // RK4 at the configured 1 ms step: measured 4e-9 of the kinetic energy scale after 2 s.
  EXPECT_LT(drift, 1e-8 * swing);
}

TEST(TwinPlant, StepIsConvergedFarBelowTheEncoderResolution) {
  TwinConfig c = config();
  c.effects.disable_all();
  c.effects.coulomb = true;  // the stiffest smooth term of the rigid plant
  const auto truth = make_truth<Model>(c);
  Plant<Model>::Vec q0, tau;
  q0 << 0.3, 0.8, -0.4, -1.2, 0.5, 0.7, -0.3, 0.2;
  tau << 0.2, 1.0, 0.1, 0.5, 0.05, 0.05, 0.02, 0.01;
  Plant<Model> coarse(truth, c, q0);
  TwinConfig fine_c = c;
  fine_c.max_step = c.max_step / 16;
  Plant<Model> fine(truth, fine_c, q0);
  double worst = 0;
  for (int k = 0; k < 1000; ++k) {
    const Plant<Model>::Vec t = tau * std::sin(0.01 * k);  // a held, changing command
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
  const auto truth = make_truth<Model>(c);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(n);
  q(3) = -M_PI / 2;
  Eigen::Matrix<double, n, n> M;
  Model::inertia(q, truth.phi, M);
  for (int j = 0; j < n; ++j)
    EXPECT_NEAR(c.controller.realization_inertia(j), M(j, j), 0.1 * M(j, j)) << "joint " << j + 1;
}

}  // namespace
