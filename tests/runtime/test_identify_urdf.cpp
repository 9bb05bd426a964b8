// URDF export (model_export/urdf_export.hpp, dynid export --urdf), read back with urdfdom: random
// consistent standard parameters -> base vector -> consistent standard parameters nearest a
// prior -> URDF file -> urdf::parseURDFFile. Each link's mass, CoM and inertia are the written
// ones; the joints' origins and axes, composed here from the parsed model, give the generated
// forward kinematics and every modified-DH frame; the inertials mapped back to frame-origin
// parameters (with FV, FS from the joints and IA from the standard YAML) give the base vector.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <urdf_parser/urdf_parser.h>

#include <symoro/crane_x7.hpp>
#include <symoro/rx90.hpp>
#include <symoro/stanford_rrp.hpp>

#include "symoro/identify/detail/physical_consistency_model.hpp"
#include "symoro/model_export/urdf_export.hpp"
#include "symoro/io/parameters_yaml.hpp"
#include "symoro/mdh.hpp"
#include "test_support.hpp"

namespace {

using Eigen::VectorXd;
using Crane = symoro::crane_x7::Model;
using Rx90 = symoro::rx90::Model;
using Rrp = symoro::stanford_rrp::Model;
namespace id = symoro::identify;
namespace mx = symoro::model_export;

void write_file(const std::string& path, const std::string& text) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr) << path;
  std::fwrite(text.data(), 1, text.size(), f);
  std::fclose(f);
}

Eigen::Isometry3d pose_of(const urdf::Pose& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z).toRotationMatrix();
  T.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  return T;
}

// The pose of every URDF link (by model frame number) at q, composed from the parsed joints:
// origin, then the motion along the joint axis.
template <class Model>
std::vector<Eigen::Isometry3d> urdf_frames(const urdf::ModelInterface& m, const mx::UrdfDescription& d,
                                           const VectorXd& q) {
  std::vector<Eigen::Isometry3d> T(Model::frames.size() + 1, Eigen::Isometry3d::Identity());
  int k = 0;
  for (int f = 1; f <= static_cast<int>(Model::frames.size()); ++f) {
    const auto j = m.getJoint(mx::urdf_joint_name(d, f));
    EXPECT_TRUE(j) << mx::urdf_joint_name(d, f);
    if (!j) return T;
    const Eigen::Vector3d axis(j->axis.x, j->axis.y, j->axis.z);
    Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
    if (j->type == urdf::Joint::REVOLUTE)
      motion.rotate(Eigen::AngleAxisd(q(k++), axis));
    else if (j->type == urdf::Joint::PRISMATIC)
      motion.translate(q(k++) * axis);
    const int ant = Model::frames[static_cast<std::size_t>(f - 1)].ant;
    EXPECT_EQ(j->parent_link_name, mx::urdf_link_name(d, ant));
    EXPECT_EQ(j->child_link_name, mx::urdf_link_name(d, f));
    T[static_cast<std::size_t>(f)] =
        T[static_cast<std::size_t>(ant)] * pose_of(j->parent_to_joint_origin_transform) * motion;
  }
  return T;
}

// The whole round trip on one model; `fk_frame` is the frame forward_kinematics returns.
template <class Model>
void urdf_round_trip(unsigned seed, int fk_frame) {
  symoro::test::Random rng(seed);
  const VectorXd truth = symoro::test::random_standard_parameters<Model>(rng).s;
  const VectorXd phi = Model::base_from_standard(Eigen::Matrix<double, Model::ns, 1>(truth));
  VectorXd prior = truth;
  for (Eigen::Index i = 0; i < prior.size(); ++i) prior(i) *= 1 + rng.uniform(-0.3, 0.3);
  id::ConsistencyOptions o;
  o.margin = 1e-6;
  const id::ConsistencyResult r = id::consistent_standard_parameters<Model>(phi, prior, o);
  ASSERT_TRUE(r.ok()) << r.message;

  mx::UrdfDescription d = mx::urdf_description<Model>(r.s);
  d.notes.push_back("test -- a note with a double dash");
  const std::string dir = ::testing::TempDir();
  const std::string file = dir + "/" + Model::robot_name + "_" + std::to_string(seed) + ".urdf";
  const std::string yaml = dir + "/" + Model::robot_name + "_" + std::to_string(seed) + ".standard.yaml";
  write_file(file, mx::urdf_text(d));
  write_file(yaml, mx::standard_parameters_yaml(d, "robot: test\n"));
  const urdf::ModelInterfaceSharedPtr m = urdf::parseURDFFile(file);
  ASSERT_TRUE(m) << "urdfdom could not read " << file;
  EXPECT_EQ(m->getName(), Model::robot_name);
  EXPECT_EQ(m->getRoot()->name, "base_link");
  EXPECT_EQ(m->links_.size(), Model::frames.size() + 1);
  EXPECT_EQ(m->joints_.size(), Model::frames.size());

  // Inertials: exactly the written ones (the numbers round-trip), and back to the frame origin.
  VectorXd back = VectorXd::Zero(Model::ns);
  std::vector<std::string> names;
  for (const auto& p : Model::standard_parameters) names.emplace_back(p.name);
  const VectorXd from_yaml = symoro::io::read_parameters_yaml(yaml, names);
  EXPECT_EQ((from_yaml - r.s).cwiseAbs().maxCoeff(), 0.0);
  double worst_inertial = 0;
  int with_inertial = 0;
  for (int f = 1; f <= static_cast<int>(Model::frames.size()); ++f) {
    const auto link = m->getLink(mx::urdf_link_name(d, f));
    ASSERT_TRUE(link) << mx::urdf_link_name(d, f);
    const mx::UrdfInertial want = mx::link_inertial(d, f);
    if (!want.present) {
      EXPECT_FALSE(link->inertial) << "frame " << f;
      continue;
    }
    ASSERT_TRUE(link->inertial) << "frame " << f;
    ++with_inertial;
    const urdf::Inertial& in = *link->inertial;
    mx::UrdfInertial got;
    got.present = true;
    got.mass = in.mass;
    got.com = Eigen::Vector3d(in.origin.position.x, in.origin.position.y, in.origin.position.z);
    const Eigen::Isometry3d R = pose_of(in.origin);
    EXPECT_TRUE(R.linear().isIdentity(0)) << "frame " << f;
    got.inertia << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
    worst_inertial =
        std::max({worst_inertial, std::abs(got.mass - want.mass), (got.com - want.com).cwiseAbs().maxCoeff(),
                  (got.inertia - want.inertia).cwiseAbs().maxCoeff()});
    // Consistent: positive mass, and the inertia about the CoM a PSD tensor with the triangle inequalities.
    EXPECT_GT(got.mass, 0);
    const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(got.inertia).eigenvalues();
    EXPECT_GE(ev(0), -1e-15);
    EXPECT_GE(ev(0) + ev(1), ev(2) - 1e-15);
    Eigen::Matrix3d I;
    Eigen::Vector3d h;
    double mass;
    mx::inertial_about_origin(got, I, h, mass);
    for (int k = 0; k < Model::ns; ++k) {
      const auto& p = Model::standard_parameters[static_cast<std::size_t>(k)];
      if (p.joint != f) continue;
      const std::string fam = p.family;
      if (fam == "XX") back(k) = I(0, 0);
      if (fam == "XY") back(k) = I(0, 1);
      if (fam == "XZ") back(k) = I(0, 2);
      if (fam == "YY") back(k) = I(1, 1);
      if (fam == "YZ") back(k) = I(1, 2);
      if (fam == "ZZ") back(k) = I(2, 2);
      if (fam == "MX") back(k) = h(0);
      if (fam == "MY") back(k) = h(1);
      if (fam == "MZ") back(k) = h(2);
      if (fam == "M") back(k) = mass;
    }
  }
  EXPECT_LE(worst_inertial, 1e-12);
  // Drives: FV, FS from the joints' dynamics, IA from the YAML (URDF has no field for it).
  for (int k = 0; k < Model::ns; ++k) {
    const auto& p = Model::standard_parameters[static_cast<std::size_t>(k)];
    const std::string fam = p.family;
    if (fam != "FV" && fam != "FS" && fam != "IA") continue;
    if (fam == "IA") {
      back(k) = from_yaml(k);
      continue;
    }
    const auto j = m->getJoint(mx::urdf_joint_name(d, p.joint));
    ASSERT_TRUE(j && j->dynamics) << p.name;
    back(k) = fam == "FV" ? j->dynamics->damping : j->dynamics->friction;
    EXPECT_EQ(back(k), r.s(k)) << p.name;
  }
  const VectorXd phi_back = Model::base_from_standard(Eigen::Matrix<double, Model::ns, 1>(back));
  const double base_error = (phi_back - phi).cwiseAbs().maxCoeff();
  EXPECT_LE(base_error, 1e-10 * std::max(1.0, phi.cwiseAbs().maxCoeff()));
  EXPECT_LE((back - r.s).cwiseAbs().maxCoeff(), 1e-12);

  // Joints: limits, types, and the kinematics at random poses against the generated model.
  for (int i = 0; i < Model::nq; ++i) {
    const auto& ji = Model::joints[static_cast<std::size_t>(i)];
    const auto j = m->getJoint(ji.name);
    ASSERT_TRUE(j && j->limits) << ji.name;
    EXPECT_EQ(j->limits->lower, ji.lower);
    EXPECT_EQ(j->limits->upper, ji.upper);
    EXPECT_EQ(j->limits->velocity, ji.velocity);
    EXPECT_EQ(j->limits->effort, ji.effort);
    EXPECT_EQ(j->type, ji.type == symoro::JointType::Prismatic ? urdf::Joint::PRISMATIC : urdf::Joint::REVOLUTE);
  }
  double worst_fk = 0, worst_frame = 0;
  for (int trial = 0; trial < 5; ++trial) {
    const VectorXd q = symoro::test::random_state<Model>(rng).q;
    const auto T = urdf_frames<Model>(*m, d, q);
    const Eigen::Matrix4d fk = Model::forward_kinematics(q);
    worst_fk = std::max(worst_fk, (T[static_cast<std::size_t>(fk_frame)].matrix() - fk).cwiseAbs().maxCoeff());
    // Every frame against the modified-DH chain of the model's own numbers.
    std::vector<Eigen::Isometry3d> M(Model::frames.size() + 1, Eigen::Isometry3d::Identity());
    int k = 0;
    for (std::size_t f = 1; f <= Model::frames.size(); ++f) {
      const auto& fr = Model::frames[f - 1];
      M[f] = M[static_cast<std::size_t>(fr.ant)] * symoro::mdh_transform(fr, fr.sigma == 2 ? 0.0 : q(k++));
      worst_frame = std::max(worst_frame, (T[f].matrix() - M[f].matrix()).cwiseAbs().maxCoeff());
    }
  }
  EXPECT_LE(worst_fk, 1e-12);
  EXPECT_LE(worst_frame, 1e-12);
  std::printf(
      "  %s seed %u: %d links with inertials, max inertial diff %.3g, max |B s_urdf - phi| %.3g, "
      "fk diff %.3g, frame diff %.3g, lambda_min %.3g\n",
      Model::description, seed, with_inertial, worst_inertial, base_error, worst_fk, worst_frame, r.lambda_min);
}

TEST(UrdfExport, InertialFormsAreInverse) {
  symoro::test::Random rng(1);
  Eigen::Matrix3d A;
  for (int i = 0; i < 9; ++i) A(i / 3, i % 3) = rng.uniform(-1, 1);
  const Eigen::Matrix3d I = A * A.transpose() + Eigen::Matrix3d::Identity();
  const Eigen::Vector3d h(0.3, -0.2, 0.1);
  const mx::UrdfInertial u = mx::inertial_about_com(I, h, 2.0);
  EXPECT_TRUE(u.present);
  EXPECT_LE((u.com - h / 2.0).norm(), 1e-16);
  Eigen::Matrix3d I2;
  Eigen::Vector3d h2;
  double m2;
  mx::inertial_about_origin(u, I2, h2, m2);
  EXPECT_LE((I2 - I).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_LE((h2 - h).cwiseAbs().maxCoeff(), 1e-16);
  EXPECT_EQ(m2, 2.0);
  EXPECT_FALSE(mx::inertial_about_com(Eigen::Matrix3d::Zero(), Eigen::Vector3d::Zero(), 0).present);
}

TEST(UrdfExport, RpyOfRotations) {
  symoro::test::Random rng(2);
  for (int i = 0; i < 100; ++i) {
    Eigen::Matrix3d R = Eigen::Quaterniond::UnitRandom().toRotationMatrix();
    if (i == 0)
      R = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix() *
          Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix();
    if (i == 1)
      R = Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix() *
          Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()).toRotationMatrix();
    const Eigen::Vector3d rpy = mx::urdf_rpy(R);
    const Eigen::Matrix3d back =
        (Eigen::AngleAxisd(rpy(2), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(rpy(1), Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(rpy(0), Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
    EXPECT_LE((back - R).cwiseAbs().maxCoeff(), 1e-14) << i;
  }
}

TEST(UrdfExport, RoundTripCraneX7) {  // 8 frames, the hand without inertial parameters
  for (unsigned seed = 1; seed <= 3; ++seed) urdf_round_trip<Crane>(seed, 7);
}

TEST(UrdfExport, RoundTripRx90) {
  for (unsigned seed = 1; seed <= 3; ++seed) urdf_round_trip<Rx90>(seed, 6);
}

TEST(UrdfExport, RoundTripStanfordRrp) {  // a prismatic joint
  for (unsigned seed = 1; seed <= 2; ++seed) urdf_round_trip<Rrp>(seed, 3);
}

TEST(UrdfExport, CraneX7HandIsMassless) {
  symoro::test::Random rng(4);
  const mx::UrdfDescription d = mx::urdf_description<Crane>(symoro::test::random_standard_parameters<Crane>(rng).s);
  EXPECT_FALSE(mx::link_inertial(d, 8).present);
  EXPECT_EQ(mx::urdf_link_name(d, 8), "hand_link");
  EXPECT_EQ(mx::urdf_link_name(d, 0), "base_link");
  const std::string x = mx::urdf_text(d);
  EXPECT_NE(x.find("Khalil-Kleinfinger"), std::string::npos);
  EXPECT_NE(x.find("rotor inertia IA1"), std::string::npos);
  EXPECT_NE(x.find("<link name=\"hand_link\"/>"), std::string::npos);
}

}  // namespace
