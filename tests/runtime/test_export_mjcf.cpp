// dynid export --mjcf's model against MuJoCo itself (Debian's libmujoco-dev): the identified
// parameters (phi of random physical links, through the export's consistent standard set nearest
// a perturbed prior, as dynid export computes it) written as MJCF, loaded by MuJoCo's compiler,
// and mj_inverse at random states (positions inside the limits, any velocity and acceleration)
// equal to the project's inverse dynamics within 1e-9 relative: rigid body, gravity, rotor
// inertia (armature) and viscous friction (damping). MuJoCo's dry friction is a constraint, not
// FS sign(qd): it is disabled in MuJoCo and FS set to 0 in the project's model for the
// comparison. On CRANE-X7 (a massless hand axis), the RX-90, the Stanford RRP (a prismatic
// joint) and the UR5 from its URDF, and with a payload body on the last link.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <symoro/crane_x7.hpp>
#include <symoro/rx90.hpp>
#include <symoro/stanford_rrp.hpp>
#include <symoro/ur5.hpp>

#include "symoro/identify/detail/physical_consistency_model.hpp"
#include "symoro/model_export/mjcf_export.hpp"
#include "test_support.hpp"

namespace {

using Eigen::VectorXd;
namespace id = symoro::identify;
namespace mx = symoro::model_export;

struct MujocoModel {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  ~MujocoModel() {
    if (d) mj_deleteData(d);
    if (m) mj_deleteModel(m);
  }
};

void load(const std::string& xml, const std::string& name, MujocoModel& out) {
  const std::string file = ::testing::TempDir() + "/" + name + ".xml";
  std::ofstream(file) << xml;
  char error[1000] = "";
  out.m = mj_loadXML(file.c_str(), nullptr, error, sizeof error);
  ASSERT_NE(out.m, nullptr) << "MuJoCo refused " << file << ": " << error;
  out.d = mj_makeData(out.m);
}

// The export's standard parameters of phi (random physical links' base parameters), as dynid
// export finds them: the consistent set nearest a prior 30 % off the truth.
template <class Model>
VectorXd exported_parameters(unsigned seed) {
  symoro::test::Random rng(seed);
  const VectorXd truth = symoro::test::random_standard_parameters<Model>(rng).s;
  const VectorXd phi = Model::base_from_standard(Eigen::Matrix<double, Model::ns, 1>(truth));
  VectorXd prior = truth;
  for (Eigen::Index i = 0; i < prior.size(); ++i) prior(i) *= 1 + rng.uniform(-0.3, 0.3);
  id::ConsistencyOptions o;
  o.margin = 1e-6;
  const id::ConsistencyResult r = id::consistent_standard_parameters<Model>(phi, prior, o);
  EXPECT_TRUE(r.ok()) << r.message;
  return r.s;
}

// The worst |mj_inverse - ID| / max(|ID|, 1e-3 * the torque scale) over random states.
template <class Model>
double worst_relative(const MujocoModel& mj, const VectorXd& s_without_fs, unsigned seed, int states,
                      const std::vector<mx::MjcfAttachment>& attachments = {}) {
  constexpr int n = Model::nq;
  EXPECT_EQ(mj.m->nv, n);
  EXPECT_EQ(mj.m->nu, n);
  const auto phi = Model::base_from_standard(Eigen::Matrix<double, Model::ns, 1>(s_without_fs));
  symoro::test::Random rng(seed);
  double worst = 0;
  for (int k = 0; k < states; ++k) {
    Eigen::Matrix<double, n, 1> q, qd, qdd;
    for (int j = 0; j < n; ++j) {
      const auto& ji = Model::joints[static_cast<std::size_t>(j)];
      q(j) = rng.uniform(std::max(ji.lower, -3.0), std::min(ji.upper, 3.0));
      qd(j) = rng.uniform(-2, 2);
      qdd(j) = rng.uniform(-5, 5);
    }
    for (int j = 0; j < n; ++j) {
      mj.d->qpos[j] = q(j);
      mj.d->qvel[j] = qd(j);
      mj.d->qacc[j] = qdd(j);
    }
    mj_inverse(mj.m, mj.d);
    // A payload: its standard parameters about its frame's origin added to that frame's.
    Eigen::Matrix<double, Model::ns, 1> extra = Eigen::Matrix<double, Model::ns, 1>::Zero();
    for (const mx::MjcfAttachment& a : attachments) {
      mx::UrdfInertial in = a.inertial;
      in.com = a.pose * a.inertial.com;
      in.inertia = a.pose.linear() * a.inertial.inertia * a.pose.linear().transpose();
      Eigen::Matrix3d I;
      Eigen::Vector3d h;
      double m = 0;
      mx::inertial_about_origin(in, I, h, m);
      const std::map<std::string, double> value = {{"XX", I(0, 0)}, {"XY", I(0, 1)}, {"XZ", I(0, 2)}, {"YY", I(1, 1)},
                                                   {"YZ", I(1, 2)}, {"ZZ", I(2, 2)}, {"MX", h(0)},    {"MY", h(1)},
                                                   {"MZ", h(2)},    {"M", m}};
      for (int i = 0; i < Model::ns; ++i) {
        const auto& p = Model::standard_parameters[static_cast<std::size_t>(i)];
        if (p.joint == a.frame && value.count(p.family)) extra(i) += value.at(p.family);
      }
    }
    const Eigen::Matrix<double, n, 1> tau = Model::inverse_dynamics(
        q, qd, qdd, attachments.empty() ? phi : Model::base_from_standard(s_without_fs + extra));
    const Eigen::Map<const Eigen::Matrix<double, n, 1>> got(mj.d->qfrc_inverse);
    const double scale = std::max(tau.cwiseAbs().maxCoeff(), 1e-3);
    worst = std::max(worst, (got - tau).cwiseAbs().maxCoeff() / scale);
  }
  return worst;
}

template <class Model>
VectorXd without_coulomb(VectorXd s) {
  for (int i = 0; i < Model::ns; ++i)
    if (std::string(Model::standard_parameters[static_cast<std::size_t>(i)].family) == "FS") s(i) = 0;
  return s;
}

template <class Model>
void check_against_mujoco(unsigned seed, const std::vector<mx::MjcfAttachment>& attachments = {}) {
  const VectorXd s = exported_parameters<Model>(seed);
  const mx::UrdfDescription d = mx::urdf_description<Model>(s);
  const std::string xml = mx::mjcf_text(d, symoro::test::gravity_vector<Model>(), attachments);
  MujocoModel mj;
  load(xml, std::string(Model::robot_name) + "_" + std::to_string(seed), mj);
  if (!mj.m) return;
  mj.m->opt.disableflags |= mjDSBL_FRICTIONLOSS;
  // The joints' armature, damping and range as written.
  for (int j = 0; j < Model::nq; ++j) {
    const auto& ji = Model::joints[static_cast<std::size_t>(j)];
    EXPECT_EQ(mj.m->jnt_range[2 * j], ji.lower);
    EXPECT_EQ(mj.m->jnt_range[2 * j + 1], ji.upper);
    EXPECT_EQ(mj.m->actuator_forcerange[2 * j + 1], ji.effort);
  }
  const double worst = worst_relative<Model>(mj, without_coulomb<Model>(s), seed + 1, 200, attachments);
  std::printf("%s (seed %u%s): worst |mj_inverse - ID| relative %.3g over 200 random states\n", Model::robot_name, seed,
              attachments.empty() ? "" : ", with a payload", worst);
  EXPECT_LT(worst, 1e-9);
}

TEST(ExportMjcf, MujocosInverseDynamicsEqualsTheModelsOnCraneX7) { check_against_mujoco<symoro::crane_x7::Model>(3); }
TEST(ExportMjcf, MujocosInverseDynamicsEqualsTheModelsOnTheRx90) { check_against_mujoco<symoro::rx90::Model>(4); }
TEST(ExportMjcf, MujocosInverseDynamicsEqualsTheModelsWithAPrismaticJoint) {
  check_against_mujoco<symoro::stanford_rrp::Model>(5);
}

// The UR5 as symoroc model makes it from its URDF (fixed frames, rpy offsets): the model of
// tests/runtime/bag_to_mjcf_cli.cmake, whose loaded robot writes the same MJCF text.
TEST(ExportMjcf, MujocosInverseDynamicsEqualsTheModelsOnTheUr5FromItsUrdf) {
  check_against_mujoco<symoro::ur5::Model>(8);
}

TEST(ExportMjcf, APayloadBodyRidesOnItsFrameAtTheFlangesPose) {
  mx::MjcfAttachment a;
  a.name = "payload";
  a.frame = 6;
  a.pose = Eigen::Translation3d(0.01, -0.02, 0.08) * Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized());
  a.inertial.present = true;
  a.inertial.mass = 2.5;
  a.inertial.com = {0.02, 0.01, 0.05};
  a.inertial.inertia << 0.012, 0.001, -0.0005, 0.001, 0.010, 0.0008, -0.0005, 0.0008, 0.008;
  check_against_mujoco<symoro::rx90::Model>(6, {a});
}

// What MuJoCo would refuse is refused first, naming the frame.
TEST(ExportMjcf, InertiaNoBodyHasIsRefusedNamingTheFrame) {
  using Rx90 = symoro::rx90::Model;
  VectorXd s = exported_parameters<Rx90>(7);
  for (int i = 0; i < Rx90::ns; ++i)
    if (Rx90::standard_parameters[static_cast<std::size_t>(i)].joint == 3 &&
        std::string(Rx90::standard_parameters[static_cast<std::size_t>(i)].family) == "XX")
      s(i) = -1;
  try {
    mx::mjcf_text(mx::urdf_description<Rx90>(s), Eigen::Vector3d(0, 0, -9.81));
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("frame 3"), std::string::npos) << e.what();
  }
}

}  // namespace
