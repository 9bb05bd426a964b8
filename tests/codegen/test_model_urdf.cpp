// symoroc model from a URDF against KDL (liborocos-kdl), an independent rigid-body library: the
// test builds KDL's chain itself from urdfdom's parse, the way kdl_parser does (one segment per
// joint on the way from base to tip, fixed ones included), and merges the links hanging off the
// chain with KDL's own inertia algebra. The inverse dynamics and the inertia matrix of the model
// symoroc wrote (loaded like any robot folder, its nominal standard parameters mapped through its
// base_from_standard) must equal KDL's at random states. Three public arms (tests/urdf) and one
// written here with a prismatic joint, rpy origins, a non-z axis, a negative axis, a fixed link
// and a locked off-chain joint.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <set>

#include <kdl/chain.hpp>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <urdf_parser/urdf_parser.h>

#include "../removed_at_exit.hpp"
#include "dynid_urdf_into.hpp"
#include "relative_difference.hpp"
#include "symoro/codegen/graph_evaluator.hpp"
#include "symoro/codegen/modeling.hpp"
#include "symoro/codegen/robot_name.hpp"
#include "symoro/codegen/robot_model.hpp"

namespace symoro::codegen {
namespace {

namespace fs = std::filesystem;
const fs::path kUrdfs = SYMORO_TEST_URDF_DIR;

KDL::Frame frame(const urdf::Pose& p) {
  return KDL::Frame(KDL::Rotation::Quaternion(p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w),
                    KDL::Vector(p.position.x, p.position.y, p.position.z));
}

// A link's own inertia, in its frame.
KDL::RigidBodyInertia inertia(const urdf::Link& l) {
  if (!l.inertial) return KDL::RigidBodyInertia::Zero();
  const auto& i = *l.inertial;
  return frame(i.origin) * KDL::RigidBodyInertia(i.mass, KDL::Vector::Zero(),
                                                 KDL::RotationalInertia(i.ixx, i.iyy, i.izz, i.ixy, i.ixz, i.iyz));
}

// A joint's motion at position q.
KDL::Frame motion(const urdf::Joint& j, double q) {
  const KDL::Vector a(j.axis.x, j.axis.y, j.axis.z);
  if (j.type == urdf::Joint::PRISMATIC) return KDL::Frame(q * a / a.Norm());
  if (j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::CONTINUOUS) return KDL::Frame(KDL::Rotation::Rot(a, q));
  return KDL::Frame::Identity();
}

// KDL's chain from base to tip; links off the way are merged into the link they hang from,
// their moving joints at `locked` positions (default 0).
KDL::Chain kdl_chain(const urdf::ModelInterface& m, const std::string& base, const std::string& tip,
                     const std::map<std::string, double>& locked) {
  std::vector<urdf::JointConstSharedPtr> way;
  for (auto l = m.getLink(tip); l->name != base; l = l->getParent()) way.insert(way.begin(), l->parent_joint);
  std::set<std::string> on_way;
  for (const auto& j : way) on_way.insert(j->child_link_name);
  // The inertia of a link and everything hanging off it, in the link's frame.
  std::function<KDL::RigidBodyInertia(const urdf::Link&)> lump = [&](const urdf::Link& l) {
    KDL::RigidBodyInertia I = inertia(l);
    for (const auto& c : l.child_links) {
      if (on_way.count(c->name)) continue;
      const auto it = locked.find(c->parent_joint->name);
      const double q = it == locked.end() ? 0.0 : it->second;
      I = I + (frame(c->parent_joint->parent_to_joint_origin_transform) * motion(*c->parent_joint, q)) * lump(*c);
    }
    return I;
  };
  KDL::Chain chain;
  chain.addSegment(
      KDL::Segment("base", KDL::Joint(KDL::Joint::Fixed), KDL::Frame::Identity(), KDL::RigidBodyInertia::Zero()));
  for (const auto& j : way) {
    const KDL::Frame F = frame(j->parent_to_joint_origin_transform);
    KDL::Joint joint(j->name, KDL::Joint::Fixed);
    const KDL::Vector axis = F.M * KDL::Vector(j->axis.x, j->axis.y, j->axis.z);
    if (j->type == urdf::Joint::REVOLUTE || j->type == urdf::Joint::CONTINUOUS)
      joint = KDL::Joint(j->name, F.p, axis / axis.Norm(), KDL::Joint::RotAxis);
    else if (j->type == urdf::Joint::PRISMATIC)
      joint = KDL::Joint(j->name, F.p, axis / axis.Norm(), KDL::Joint::TransAxis);
    chain.addSegment(KDL::Segment(j->child_link_name, joint, F, lump(*m.getLink(j->child_link_name))));
  }
  return chain;
}

struct Case {
  std::string label;
  fs::path urdf;
  ModelingOptions options;
  double tolerance = 1e-12;  // relative
};

using test::relative_difference;

void expect_matches_kdl(const Case& c) {
  SCOPED_TRACE(c.label);
  const Modeling m = model_from_urdf(c.urdf.string(), c.options);
  const fs::path dir = symoro::test::removed_at_exit("symoro_urdf_" + std::to_string(::getpid())) / m.robot;
  fs::create_directories(dir);
  for (const auto& f : m.files) std::ofstream(dir / f.name) << f.text;
  RobotModel ours = load_robot(dir.string());

  const auto model = urdf::parseURDFFile(c.urdf.string());
  ASSERT_TRUE(model);
  const std::string base = c.options.base_link.empty() ? model->getRoot()->name : c.options.base_link;
  const KDL::Chain chain = kdl_chain(*model, base, ours.spec.urdf.tip_link, c.options.locked);
  const int n = static_cast<int>(chain.getNrOfJoints());
  ASSERT_EQ(n, ours.n);
  ASSERT_EQ(ours.spec.urdf.base_link, base);

  // The URDF's inertials (the nominal standard parameters), without friction or rotor inertia:
  // KDL has neither.
  std::map<std::string, double> standard = ours.spec.nominal;
  for (auto& [name, v] : standard)
    if (name.rfind("FV", 0) == 0 || name.rfind("FS", 0) == 0 || name.rfind("IA", 0) == 0) v = 0;
  for (const auto& [k, v] : ours.spec.constants) standard[k] = v;
  ASSERT_EQ(ours.spec.nominal.size(), ours.standard.size());
  const std::vector<double> base_values = Evaluator(ours.graph, ours.base_from_standard)(standard);

  std::vector<NodeId> roots = ours.idm;
  for (const auto& row : ours.inm) roots.insert(roots.end(), row.begin(), row.end());
  Evaluator eval(ours.graph, roots);
  KDL::ChainIdSolver_RNE rne(chain, KDL::Vector(0, 0, -ours.spec.constants.at("G3")));
  KDL::ChainDynParam dyn(chain, KDL::Vector(0, 0, -ours.spec.constants.at("G3")));
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 25; ++trial) {
    KDL::JntArray q(n), qd(n), qdd(n), tau(n);
    std::map<std::string, double> at;
    for (std::size_t p = 0; p < ours.base.size(); ++p) at[ours.base[p].name] = base_values[p];
    for (int j = 0; j < n; ++j) {
      q(j) = 1.5 * u(rng);
      qd(j) = 2 * u(rng);
      qdd(j) = 3 * u(rng);
      at[ours.q[j]] = q(j);
      at[ours.qd[j]] = qd(j);
      at[ours.qdd[j]] = qdd(j);
    }
    ASSERT_GE(rne.CartToJnt(q, qd, qdd, KDL::Wrenches(chain.getNrOfSegments(), KDL::Wrench::Zero()), tau), 0);
    KDL::JntSpaceInertiaMatrix H(n);
    ASSERT_GE(dyn.JntToMass(q, H), 0);
    const std::vector<double> v = eval(at);
    std::vector<double> kdl_tau(n), our_tau(v.begin(), v.begin() + n), kdl_M, our_M(v.begin() + n, v.end());
    for (int j = 0; j < n; ++j) kdl_tau[j] = tau(j);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) kdl_M.push_back(H(i, j));
    EXPECT_LT(relative_difference(kdl_tau, our_tau), c.tolerance) << "inverse dynamics, trial " << trial;
    EXPECT_LT(relative_difference(kdl_M, our_M), c.tolerance) << "inertia matrix, trial " << trial;
  }
}

TEST(ModelFromUrdf, PandaMatchesKdl) {
  Case c{"panda to its hand, fingers locked at 0", kUrdfs / "panda.urdf", {}};
  c.options.tip_link = "panda_hand";
  expect_matches_kdl(c);
  c.label = "panda to link 7, fingers locked open";
  c.options.tip_link = "panda_link7";
  c.options.locked = {{"panda_finger_joint1", 0.03}, {"panda_finger_joint2", 0.01}};
  expect_matches_kdl(c);
}

TEST(ModelFromUrdf, Ur5MatchesKdl) { expect_matches_kdl({"ur5", kUrdfs / "ur5_robot.urdf", {}, 1e-9}); }

// The Kinova's and the UR5's rpy are quarter turns to 11 digits (1.57079632679: 5e-12 rad
// short), and symoroc model takes them as quarter turns (within 1e-8 rad: exact zeros in the
// model), so its model is that much off the files' literal geometry: 1e-9, not 1e-12.
TEST(ModelFromUrdf, KinovaMatchesKdl) { expect_matches_kdl({"kinova jaco2", kUrdfs / "kinova.urdf", {}, 1e-9}); }

// Any URDF, named by the environment (SYMORO_URDF, and SYMORO_URDF_TIP / SYMORO_URDF_BASE when
// the chain's ends must be named): a user's arm checked against KDL. Unset, the Panda cut at
// link 5: its wrist joints 6 and 7 and the fingers, beyond the tip, are locked at 0 and merged.
TEST(ModelFromUrdf, TheUrdfNamedByTheEnvironmentMatchesKdl) {
  const char* path = std::getenv("SYMORO_URDF");
  Case c{path ? path : "panda cut at link 5", path ? fs::path(path) : kUrdfs / "panda.urdf", {}, path ? 1e-9 : 1e-12};
  if (!path) c.options.tip_link = "panda_link5";
  if (const char* tip = std::getenv("SYMORO_URDF_TIP")) c.options.tip_link = tip;
  if (const char* base = std::getenv("SYMORO_URDF_BASE")) c.options.base_link = base;
  expect_matches_kdl(c);
}

// Every case the conversion has to get right, in one small arm: rpy joint origins, an axis along
// x, a negative axis, an oblique axis, a prismatic joint, a fixed link on the chain, a locked
// off-chain revolute joint with its own link, and a base link that is not the root.
const char* kTestArm = R"(<?xml version="1.0"?>
<robot name="test_arm">
  <link name="world"/>
  <joint name="mount" type="fixed"><parent link="world"/><child link="base"/><origin xyz="0.1 0 0.2" rpy="0.1 0 0"/></joint>
  <link name="base"><inertial><mass value="3"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><origin xyz="0 0 0.3" rpy="0 0 0.4"/>
    <axis xyz="0 0 -1"/><limit lower="-3" upper="3" velocity="2" effort="50"/></joint>
  <link name="l1"><inertial><origin xyz="0.02 0.01 -0.05" rpy="0.3 0.2 0.1"/><mass value="2.5"/>
    <inertia ixx="0.02" ixy="0.001" ixz="-0.002" iyy="0.025" iyz="0.003" izz="0.01"/></inertial></link>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.05 0.02 0.1" rpy="1.5707963267948966 0 0.2"/>
    <axis xyz="1 0 0"/><limit lower="-2" upper="2" velocity="2" effort="40"/><dynamics damping="0.2" friction="0.1"/></joint>
  <link name="l2"><inertial><origin xyz="0.1 -0.02 0.03" rpy="0 0.5 0"/><mass value="1.8"/>
    <inertia ixx="0.01" ixy="-0.001" ixz="0.001" iyy="0.03" iyz="0.002" izz="0.028"/></inertial></link>
  <joint name="j3" type="prismatic"><parent link="l2"/><child link="l3"/><origin xyz="0.3 0 0" rpy="0 -0.3 0.1"/>
    <axis xyz="0 0.6 0.8"/><limit lower="-0.1" upper="0.2" velocity="0.5" effort="100"/></joint>
  <link name="l3"><inertial><origin xyz="0 0.04 0.02"/><mass value="1.1"/>
    <inertia ixx="0.004" ixy="0" ixz="0.0005" iyy="0.005" iyz="0" izz="0.003"/></inertial></link>
  <joint name="l3_plate" type="fixed"><parent link="l3"/><child link="plate"/><origin xyz="0 0 0.15" rpy="0.2 0.1 0"/></joint>
  <link name="plate"><inertial><origin xyz="0.01 0 0"/><mass value="0.4"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.002"/></inertial></link>
  <joint name="j4" type="continuous"><parent link="plate"/><child link="l4"/><origin xyz="0.02 0.05 0.04" rpy="-0.5 0.7 1.1"/>
    <axis xyz="0.3 -0.5 0.2"/><limit velocity="3" effort="10"/></joint>
  <link name="l4"><inertial><origin xyz="0.03 0.02 0.06" rpy="0.1 0.2 0.3"/><mass value="0.9"/>
    <inertia ixx="0.003" ixy="0.0002" ixz="0.0001" iyy="0.004" iyz="-0.0003" izz="0.002"/></inertial></link>
  <joint name="side" type="revolute"><parent link="l4"/><child link="flap"/><origin xyz="0.05 0 0.02"/>
    <axis xyz="0 1 0"/><limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
  <link name="flap"><inertial><origin xyz="0.04 0 0"/><mass value="0.3"/>
    <inertia ixx="0.0002" ixy="0" ixz="0" iyy="0.0004" iyz="0" izz="0.0004"/></inertial></link>
  <joint name="j5" type="revolute"><parent link="l4"/><child link="l5"/><origin xyz="0 0 0.12" rpy="0 1.5707963267948966 0"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" velocity="3" effort="5"/></joint>
  <link name="l5"><inertial><origin xyz="0.01 0.01 0.02"/><mass value="0.5"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.0008"/></inertial></link>
</robot>
)";

TEST(ModelFromUrdf, EveryKindOfJointMatchesKdl) {
  const fs::path p = symoro::test::removed_at_exit("symoro_test_arm_" + std::to_string(::getpid()) + ".urdf");
  std::ofstream(p) << kTestArm;
  Case c{"test arm", p, {}};
  c.options.base_link = "base";
  c.options.tip_link = "l5";
  c.options.locked = {{"side", 0.6}};
  expect_matches_kdl(c);
}

}  // namespace
}  // namespace symoro::codegen

namespace symoro::codegen {
namespace {

// The message of the error model_from_urdf raises on `text`.
std::string error_of(const std::string& text, ModelingOptions o = {}) {
  const fs::path p = symoro::test::removed_at_exit("symoro_bad_" + std::to_string(::getpid()) + ".urdf");
  std::ofstream(p) << text;
  try {
    model_from_urdf(p.string(), o);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

std::string arm(const std::string& joint2) {
  return std::string(
             R"(<robot name="a"><link name="b"/><link name="l1"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
<joint name="j1" type="revolute"><parent link="b"/><child link="l1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
<link name="l2"/>)") +
         (joint2.find("\"l3\"") != std::string::npos ? "<link name=\"l3\"/>" : "") + joint2 + "</robot>";
}

// Sizes no serial arm has: elements nested 100,000 deep (the XML parser's recursion crashed
// symoroc after 18 s), 2,001 links (minutes of chain search), a chain of 100 moving joints.
TEST(ModelFromUrdf, SizesNoArmHasAreRefusedAtOnce) {
  const int deep = 100000;
  std::string nested = "<robot name=\"r\">\n<link name=\"l0\"/>\n";
  for (int k = 0; k < deep; ++k) nested += "<a>";
  for (int k = 0; k < deep; ++k) nested += "</a>";
  nested += "\n</robot>\n";
  const std::string too_deep = error_of(nested);
  EXPECT_NE(too_deep.find(".urdf:3:"), std::string::npos) << too_deep;
  EXPECT_NE(too_deep.find("elements nested more than 100 deep"), std::string::npos) << too_deep;
  const auto chain = [](int links) {
    std::string t = "<robot name=\"r\">\n<link name=\"l0\"/>\n";
    for (int i = 1; i < links; ++i)
      t += fmt::format(
          R"(<link name="l{}"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
<joint name="j{}" type="revolute"><parent link="l{}"/><child link="l{}"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
)",
          i, i, i - 1, i);
    return t + "</robot>\n";
  };
  const std::string many = error_of(chain(2001));
  EXPECT_NE(many.find("2001 links: more than the 2000"), std::string::npos) << many;
  const std::string long_chain = error_of(chain(101));
  EXPECT_NE(long_chain.find("100 moving joints between 'l0' and 'l100': symoroc models serial arms of at most 64"),
            std::string::npos)
      << long_chain;
  EXPECT_NE(long_chain.find(".urdf:132:"), std::string::npos) << long_chain;  // the 65th joint's line
}

TEST(ModelFromUrdf, BadInputIsNamed) {
  const std::string malformed = error_of("<robot name=\"a\">\n<link name=\"b\">\n</robot>");
  EXPECT_NE(malformed.find(".urdf:3:"), std::string::npos) << malformed;  // where the mismatch is
  EXPECT_NE(malformed.find("malformed XML"), std::string::npos) << malformed;
  EXPECT_NE(error_of("<robot name=\"a\"><link name=\"b\"/><link name=\"c\"/></robot>").find("not a valid URDF"),
            std::string::npos);
  const std::string floating =
      error_of(arm(R"(<joint name="free" type="floating"><parent link="l1"/><child link="l2"/></joint>)"));
  EXPECT_NE(floating.find("joint 'free' on the chain is floating"), std::string::npos) << floating;
  EXPECT_NE(floating.find(".urdf:3:"), std::string::npos) << floating;  // the joint's line
  const std::string branch = error_of(arm(
      R"(<joint name="x" type="revolute"><parent link="l1"/><child link="l2"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
<joint name="y" type="revolute"><parent link="l1"/><child link="l3"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" velocity="1" effort="1"/></joint>)"));
  EXPECT_NE(branch.find("'l1' branches into moving joints ('x' and 'y')"), std::string::npos) << branch;
  ModelingOptions tip;
  tip.tip_link = "l2";
  const std::string mimic = error_of(
      arm(R"(<joint name="m" type="revolute"><parent link="l1"/><child link="l2"/><axis xyz="0 0 1"/><mimic joint="j1"/><limit lower="-1" upper="1" velocity="1" effort="1"/></joint>)"),
      tip);
  EXPECT_NE(mimic.find("joint 'm' on the chain mimics 'j1'"), std::string::npos) << mimic;
  tip.tip_link = "nowhere";
  const std::string fixed = R"(<joint name="f" type="fixed"><parent link="l1"/><child link="l2"/></joint>)";
  EXPECT_NE(error_of(arm(fixed), tip).find("the tip link 'nowhere' is not a link"), std::string::npos);
  ModelingOptions lock;
  lock.locked = {{"j1", 0.1}};
  EXPECT_NE(error_of(arm(fixed), lock).find("--lock j1: not a moving joint off the chain"), std::string::npos);
  // An inconsistent inertial is a warning that names the link, not an error.
  const fs::path p = symoro::test::removed_at_exit("symoro_warn_" + std::to_string(::getpid()) + ".urdf");
  std::ofstream(p)
      << R"(<robot name="w"><link name="b"/><link name="l1"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="3"/></inertial></link>
<joint name="j1" type="revolute"><parent link="b"/><child link="l1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" velocity="1" effort="1"/></joint></robot>)";
  const Modeling m = model_from_urdf(p.string());
  bool warned = false;
  for (const auto& note : m.notes)
    warned = warned || note.find("link 'l1' (line 1) is not physically consistent") != std::string::npos;
  EXPECT_TRUE(warned);
}

// Values urdfdom takes without a word (issue 42, item 13): a NaN, infinite, textual or empty inertia
// became 0, a NaN mass dropped the whole inertial, 1e300 was accepted and an origin of 1e300 wrote
// nan into robot.yaml; inverted limits became +-pi; a xacro macro was ignored. Each is an error
// naming the line, the link or joint, the attribute and the value.
TEST(ModelFromUrdf, ValuesUrdfdomTakesSilentlyAreRefusedWhereTheyAre) {
  // arm() with the first link's inertial, the first joint's origin or its limits replaced.
  auto with = [](const std::string& from, const std::string& to) {
    std::string a = arm(
        R"(<joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" velocity="1" effort="1"/></joint>)");
    const std::size_t at = a.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return a.replace(at, from.size(), to);
  };
  const std::string ixx = R"(ixx="1")", mass = R"(<mass value="1"/>)";
  for (const std::string bad : {"nan", "inf", "-inf", "heavy", "", "1e300", "1 2"}) {
    const std::string e = error_of(with(ixx, "ixx=\"" + bad + "\""));
    EXPECT_NE(e.find(".urdf:1:"), std::string::npos) << bad << ": " << e;
    EXPECT_NE(e.find("link 'l1': <inertia ixx=\"" + bad + "\">"), std::string::npos) << bad << ": " << e;
  }
  for (const std::string bad : {"nan", "-1", "1e300", "one"}) {
    const std::string e = error_of(with(mass, "<mass value=\"" + bad + "\"/>"));
    EXPECT_NE(e.find("link 'l1': <mass value=\"" + bad + "\">"), std::string::npos) << bad << ": " << e;
  }
  EXPECT_NE(error_of(with(R"(ixy="0" )", "")).find("link 'l1': <inertia> has no ixy"), std::string::npos);
  const std::string far = error_of(with(R"(<axis xyz="0 0 1"/><limit lower="-1" upper="1")",
                                        R"(<origin xyz="1e300 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1")"));
  EXPECT_NE(far.find(".urdf:2:"), std::string::npos) << far;
  EXPECT_NE(far.find("joint 'j1': <origin xyz=\"1e300 0 0\">: 1e300 is beyond +-1000 m"), std::string::npos) << far;
  const std::string rpy = error_of(with(R"(<axis xyz="0 0 1"/><limit lower="-1" upper="1")",
                                        R"(<origin rpy="0 nan 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1")"));
  EXPECT_NE(rpy.find("joint 'j1': <origin rpy=\"0 nan 0\">: 'nan' is not a finite number"), std::string::npos) << rpy;
  const std::string inverted = error_of(with(R"(<limit lower="-1" upper="1")", R"(<limit lower="2" upper="-2")"));
  EXPECT_NE(inverted.find("joint 'j1': <limit lower=\"2\" upper=\"-2\"> has its lower limit above its upper one"),
            std::string::npos)
      << inverted;
  EXPECT_NE(
      error_of(with(R"(velocity="1")", R"(velocity="-3")")).find("joint 'j1': <limit velocity=\"-3\"> is outside 0"),
      std::string::npos);
  const std::string xacro =
      error_of(with(R"(<link name="l2"/>)", "<xacro:include filename=\"hand.xacro\"/>\n<link name=\"l2\"/>"));
  EXPECT_NE(xacro.find("<xacro:include> is a xacro macro: expand the file with xacro first"), std::string::npos)
      << xacro;
  const std::string expression = error_of(with(R"(velocity="1")", R"(velocity="${v_max}")"));
  EXPECT_NE(expression.find("holds a xacro expression"), std::string::npos) << expression;

  // --lock: a position outside the locked joint's limits, and no position at all.
  const std::string finger = arm(
      R"(<joint name="f" type="prismatic"><parent link="l1"/><child link="l2"/><axis xyz="1 0 0"/><limit lower="0" upper="0.04" velocity="1" effort="1"/></joint>)");
  ModelingOptions lock;
  lock.tip_link = "l1";  // the finger hangs off the chain
  lock.locked = {{"f", -5}};
  const std::string outside = error_of(finger, lock);
  EXPECT_NE(outside.find(".urdf:3:"), std::string::npos) << outside;
  EXPECT_NE(outside.find("--lock f=-5: outside the joint's limits 0 .. 0.04"), std::string::npos) << outside;
  lock.locked = {{"f", 0.02}};
  EXPECT_EQ(error_of(finger, lock), "no error");
  for (const std::string spec : {"=", "=abc", "f=", "f=nan", "f=1e300", "f", "f=0.01m"}) {
    ModelingOptions o;
    try {
      add_lock(o, spec);
      ADD_FAILURE() << spec << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).rfind("--lock '" + spec + "': ", 0), 0u) << e.what();
    }
  }
  ModelingOptions o;
  add_lock(o, "f= 0.02 ");
  EXPECT_EQ(o.locked.at("f"), 0.02);
}

// Usable input the model changes is said on the console (Modeling::notes): names that are no C++
// identifier, and empty limits.
TEST(ModelFromUrdf, NamesAndLimitsTheModelChangesAreWarnedAbout) {
  const fs::path p = symoro::test::removed_at_exit("symoro_names_" + std::to_string(::getpid()) + ".urdf");
  std::ofstream(p)
      << R"(<robot name="bras-léger"><link name="b"/><link name="l1"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
<joint name="épaule" type="revolute"><parent link="b"/><child link="l1"/><axis xyz="0 0 1"/><limit lower="0" upper="0" velocity="1" effort="1"/></joint></robot>)";
  const Modeling m = model_from_urdf(p.string());
  std::string notes;
  for (const auto& n : m.notes) notes += n + "\n";
  EXPECT_NE(notes.find("the robot's name 'bras-léger' is no C++ identifier: written as 'bras_l__ger'"),
            std::string::npos)
      << notes;
  EXPECT_NE(notes.find("joint 'épaule' (line 2) is no C++ identifier: robot.yaml names it '__paule'"),
            std::string::npos)
      << notes;
  EXPECT_NE(notes.find("joint 'épaule' (line 2) has empty limits (0 .. 0): robot.yaml gets -pi .. pi"),
            std::string::npos)
      << notes;
}

// The folder's name is the robot's namespace: `class`, `int` or `std` generated code that did not
// compile.
TEST(RobotName, KeywordsAndNamesTheGeneratedCodeUsesAreRefused) {
  for (const std::string bad :
       {"class", "int", "std", "Eigen", "detail", "and", "co_await", "a__b", "_Arm", "2arm", "arm-2", "bras_é", ""})
    EXPECT_NE(robot_name_problem(bad), "") << bad;
  for (const std::string good : {"crane_x7", "ur5", "Panda", "_arm", "classic", "integer", "stdarm"})
    EXPECT_EQ(robot_name_problem(good), "") << good;
  EXPECT_NE(robot_name_problem("class").find("is a C++ keyword"), std::string::npos);
}

}  // namespace
}  // namespace symoro::codegen

// dynid export --into: identified standard parameters written into the user's own URDF. Read
// back through symoroc model, the file gives every model link's standard parameters again
// (so the base parameters too); with the <inertial> and <dynamics> elements taken out, the file
// is the user's, byte for byte.

namespace symoro::codegen {
namespace {

std::string without_dynamic_elements(std::string x) {
  for (const std::string tag : {"inertial", "dynamics"}) {
    std::size_t at;
    while ((at = x.find("<" + tag)) != std::string::npos) {
      const std::size_t gt = x.find('>', at);
      const std::size_t end = x[gt - 1] == '/' ? gt + 1 : x.find("</" + tag + ">", gt) + tag.size() + 3;
      std::size_t from = at;
      while (from > 0 && (x[from - 1] == ' ' || x[from - 1] == '\t')) --from;  // its indentation
      std::size_t to = end;
      if (to < x.size() && x[to] == '\n') ++to;
      x.erase(from, to - from);
    }
  }
  return x;
}

void expect_written_into(double extra_mass, bool expect_whole) {
  ModelingOptions o;
  o.tip_link = "panda_hand";
  o.locked = {{"panda_finger_joint1", 0.02}, {"panda_finger_joint2", 0.02}};
  const fs::path user = kUrdfs / "panda.urdf";
  const Modeling m = model_from_urdf(user.string(), o);
  const fs::path dir = symoro::test::removed_at_exit("symoro_into_" + std::to_string(::getpid())) / m.robot;
  fs::create_directories(dir);
  for (const auto& f : m.files) std::ofstream(dir / f.name) << f.text;
  const RobotModel r = load_robot(dir.string());

  // "Identified": each model link's nominal body plus a random consistent one (or, for the last
  // link, minus mass when extra_mass < 0: less than the merged hand and fingers weigh).
  model_export::UrdfDescription d;
  d.robot = r.name;
  for (const auto& f : r.frames) d.frames.push_back({f.ant, f.sigma, f.mu, f.gamma, f.b, f.alpha, f.d, f.theta, f.r});
  for (int j = 0; j < r.n; ++j) {
    const auto& js = r.spec.joints[j];
    d.joints.push_back({js.name.c_str(), JointType::Revolute, js.lower, js.upper, js.velocity, js.effort,
                        js.audit_lower, js.audit_upper});
  }
  for (const auto& p : r.standard) d.names.push_back({p.name.c_str(), p.family.c_str(), p.joint});
  d.s.resize(static_cast<Eigen::Index>(r.standard.size()));
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  std::map<std::string, double> extra;
  for (int j = 1; j <= r.n; ++j) {
    const double mass = j == r.n ? extra_mass : 0.1 + 0.2 * u(rng);
    const double c[3] = {0.05 * u(rng), 0.05 * u(rng), 0.05 * u(rng)}, I = 1e-3 * (1 + u(rng));
    const double cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    const std::string s = std::to_string(j);
    // A point-like body with a small isotropic inertia (negative mass: a lighter link).
    extra["XX" + s] = std::abs(mass) / mass * I + mass * (cc - c[0] * c[0]);
    extra["YY" + s] = std::abs(mass) / mass * I + mass * (cc - c[1] * c[1]);
    extra["ZZ" + s] = std::abs(mass) / mass * I + mass * (cc - c[2] * c[2]);
    extra["XY" + s] = -mass * c[0] * c[1];
    extra["XZ" + s] = -mass * c[0] * c[2];
    extra["YZ" + s] = -mass * c[1] * c[2];
    extra["MX" + s] = mass * c[0];
    extra["MY" + s] = mass * c[1];
    extra["MZ" + s] = mass * c[2];
    extra["M" + s] = mass;
    extra["FV" + s] = 0.01 + u(rng);
    extra["FS" + s] = 0.01 + u(rng);
  }
  for (std::size_t i = 0; i < r.standard.size(); ++i) {
    const std::string& name = r.standard[i].name;
    d.s(static_cast<Eigen::Index>(i)) = r.spec.nominal.at(name) + (extra.count(name) ? extra.at(name) : 0.0);
  }
  std::vector<std::string> notes;
  const std::string text = dynid::urdf_into(d, (dir / "robot.yaml").string(), user.string(), notes);
  bool whole = false;
  for (const auto& n : notes) whole = whole || n.find("takes the whole body") != std::string::npos;
  EXPECT_EQ(whole, expect_whole);

  std::ifstream in(user);
  const std::string original((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(without_dynamic_elements(text), without_dynamic_elements(original));

  const fs::path written = dir / "written.urdf";
  std::ofstream(written) << text;
  const Modeling back = model_from_urdf(written.string(), o);
  const fs::path dir2 = dir.parent_path() / "back";
  fs::create_directories(dir2);
  for (const auto& f : back.files) std::ofstream(dir2 / f.name) << f.text;
  const RobotModel rb = load_robot(dir2.string());
  double scale = 0;
  for (Eigen::Index i = 0; i < d.s.size(); ++i) scale = std::max(scale, std::abs(d.s(i)));
  for (std::size_t i = 0; i < r.standard.size(); ++i) {
    const std::string& name = r.standard[i].name;
    if (name.rfind("IA", 0) == 0) continue;  // no URDF field
    EXPECT_NEAR(rb.spec.nominal.at(name), d.s(static_cast<Eigen::Index>(i)), 1e-12 * scale) << name;
  }
}

// dynid export --into a malformed URDF: its line and column, not urdfdom's "line 100 in
// ./urdf_parser/src/model.cpp" on the console (issue 42, item 17).
TEST(ModelFromUrdf, AMalformedIntoUrdfIsNamedAtItsLine) {
  ModelingOptions o;
  o.tip_link = "panda_hand";
  o.locked = {{"panda_finger_joint1", 0.02}, {"panda_finger_joint2", 0.02}};
  const Modeling m = model_from_urdf((kUrdfs / "panda.urdf").string(), o);
  const fs::path dir = symoro::test::removed_at_exit("symoro_into_bad_" + std::to_string(::getpid())) / m.robot;
  fs::create_directories(dir);
  for (const auto& f : m.files) std::ofstream(dir / f.name) << f.text;
  const fs::path mine = dir / "mine.urdf";
  std::ofstream(mine) << "<robot name=\"x\">\n<link name=\"a\">\n</robot>\n";
  std::vector<std::string> notes;
  testing::internal::CaptureStderr();
  try {
    dynid::urdf_into({}, (dir / "robot.yaml").string(), mine.string(), notes);
    ADD_FAILURE() << "a malformed URDF accepted";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(mine.string() + ":3:"), std::string::npos) << what;
    EXPECT_NE(what.find("malformed XML"), std::string::npos) << what;
  }
  // Well-formed XML that is no URDF: urdfdom's reason is not printed past the error.
  std::ofstream(mine) << "<robot name=\"x\"><link name=\"a\"/><link name=\"b\"/></robot>\n";
  EXPECT_THROW(dynid::urdf_into({}, (dir / "robot.yaml").string(), mine.string(), notes), std::exception);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

TEST(ModelFromUrdf, IdentifiedInertialsGoIntoTheUsersUrdf) {
  expect_written_into(0.2, false);
  // The identified last link weighs less than the hand and fingers merged into it: the chain
  // link takes the whole body and their inertials go.
  expect_written_into(-0.9, true);
}

}  // namespace
}  // namespace symoro::codegen
