// Generic tests of one generated robot and all its variants (symoro::<robot>::Models). Built
// once per robot folder with SYMORO_ROBOT_HEADER, SYMORO_ROBOT_NS and SYMORO_ROBOT_DIR; nothing
// here names a robot. The references are OpenSYMORO's own model files run by the grammar's
// interpreter (reference.hpp) and an independent Newton-Euler (newton_euler.hpp).
#include SYMORO_ROBOT_HEADER

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <tuple>
#include <type_traits>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <gtest/gtest.h>

#include "jet_support.hpp"
#include "symoro/grammar/parser.hpp"
#include "robot_models.hpp"
#include "test_support.hpp"

namespace symoro::test {
namespace {

// The generated code and the references evaluate the same expressions in a different order;
// 1e-9 of the object's magnitude leaves room for that round-off (about 1e-13 to 1e-15 in
// practice) and for the conditioning of M in the forward dynamics, and nothing more.
constexpr double kRelTol = 1e-9;
// Central differences with h = 1e-6: truncation about h^2 and round-off about 1e-16/h, both far
// below 1e-6 of the derivative's magnitude.
constexpr double kFdStep = 1e-6;
constexpr double kFdTol = 1e-6;
constexpr int kStates = 5;
constexpr double kSameArithmetic = 1e-14;

template <class Model>
class RobotModel : public ::testing::Test {
 protected:
  static const Reference& ref() { return reference(SYMORO_ROBOT_DIR); }
  static constexpr bool is_full = std::is_same_v<typename Model::Parent, Model>;

  // Calls check(state, phi) at kStates random states with order-1 random phi.
  template <class Check>
  void for_states(const Check& check) {
    for (int k = 0; k < kStates; ++k) {
      SCOPED_TRACE("random state " + std::to_string(k));
      const State<Model> s = random_state<Model>(rng_);
      check(s, random_phi<Model>(rng_));
    }
  }
  // phi of physical standard parameters, for the checks that invert M: the full model's M is
  // then positive definite; a variant drops its fixed entries, which leaves M invertible here.
  ParameterVector<Model> physical_phi() {
    return Model::base_from_standard(random_standard_parameters<Model>(rng_).s);
  }
  JointVector<Model> random_torque() { return rng_.vector<JointVector<Model>>(Model::nq, -5, 5); }
  // A random direction of q for the Jet checks, entries in [-1, 1], from a generator of its own:
  // the states and parameters stay those drawn from rng_.
  JointVector<Model> random_direction() { return direction_rng_.vector<JointVector<Model>>(Model::nq, -1, 1); }

  Random rng_{20240611};
  Random direction_rng_{20240612};
};
TYPED_TEST_SUITE(RobotModel, Models, ModelName);

// ---- a. OpenSYMORO's model files, interpreted -------------------------------------------------
// A variant's effect terms (robot.yaml `effects`) are not in the files: they are added from the
// hand-written formulas of test_support.hpp (effect_columns, effect_torque).

TYPED_TEST(RobotModel, RegressorMatchesDimColumnByName) {
  using M = TypeParam;
  constexpr int ne = effect_count<M>;
  const auto names = parameter_names<M>();
  this->for_states([&](const State<M>& s, const auto&) {
    Eigen::MatrixXd expected = this->ref().regressor(s.q, s.qd, s.qdd, names);
    EXPECT_TRUE(expected.rightCols(ne).isZero(0.0)) << "an effect parameter is a column of dim.txt";
    expected.rightCols(ne) = effect_columns<M>(s.q, s.qd);
    EXPECT_TRUE(close(M::regressor(s.q, s.qd, s.qdd), expected, kRelTol, names));
  });
}

TYPED_TEST(RobotModel, InverseDynamicsMatchesIdm) {
  using M = TypeParam;
  this->for_states([&](const State<M>& s, const ParameterVector<M>& phi) {
    EXPECT_TRUE(close(M::inverse_dynamics(s.q, s.qd, s.qdd, phi),
                      this->ref().inverse_dynamics(s.q, s.qd, s.qdd, parent_parameter_values<M>(phi)) +
                          effect_torque<M>(s.q, s.qd, phi),
                      kRelTol));
  });
}

TYPED_TEST(RobotModel, InertiaMatchesInm) {
  using M = TypeParam;
  this->for_states([&](const State<M>& s, const ParameterVector<M>& phi) {
    EXPECT_TRUE(close(M::inertia(s.q, phi), this->ref().inertia(s.q, parent_parameter_values<M>(phi)),
                      kRelTol));
  });
}

TYPED_TEST(RobotModel, NonlinearEffectsMatchCcg) {
  using M = TypeParam;
  this->for_states([&](const State<M>& s, const ParameterVector<M>& phi) {
    EXPECT_TRUE(close(M::nonlinear_effects(s.q, s.qd, phi),
                      this->ref().nonlinear_effects(s.q, s.qd, parent_parameter_values<M>(phi)) +
                          effect_torque<M>(s.q, s.qd, phi),
                      kRelTol));
  });
}

TYPED_TEST(RobotModel, ForwardDynamicsMatchesDdm) {
  using M = TypeParam;
  this->for_states([&](const State<M>& s, const auto&) {
    const ParameterVector<M> phi = this->physical_phi();
    const JointVector<M> tau = this->random_torque();
    // The effects' torque acts on the joints like friction: ddm.txt sees tau minus it.
    const Eigen::VectorXd net = tau - effect_torque<M>(s.q, s.qd, phi);
    EXPECT_TRUE(close(M::forward_dynamics(s.q, s.qd, tau, phi),
                      this->ref().forward_dynamics(s.q, s.qd, net, parent_parameter_values<M>(phi)),
                      kRelTol));
  });
}

TYPED_TEST(RobotModel, ForwardKinematicsMatchesFgm) {
  using M = TypeParam;
  this->for_states([&](const State<M>& s, const auto&) {
    EXPECT_TRUE(close(M::forward_kinematics(s.q), this->ref().forward_kinematics(s.q), kRelTol));
  });
}

TYPED_TEST(RobotModel, JacobianMatchesJac) {
  using M = TypeParam;
  this->for_states([&](const State<M>& s, const auto&) {
    EXPECT_TRUE(close(M::jacobian(s.q), this->ref().jacobian(s.q), kRelTol));
  });
}

// ---- b, c. Consistency of the generated functions among themselves ----------------------------

TYPED_TEST(RobotModel, RegressorTimesPhiPlusFixedTorqueIsInverseDynamics) {
  using M = TypeParam;
  this->for_states([&](const State<M>& s, const ParameterVector<M>& phi) {
    const JointVector<M> tau0 = M::fixed_torque(s.q, s.qd, s.qdd);
    EXPECT_TRUE(close(M::regressor(s.q, s.qd, s.qdd) * phi + tau0,
                      M::inverse_dynamics(s.q, s.qd, s.qdd, phi), kRelTol));
  });
}

TYPED_TEST(RobotModel, InertiaIsAffineInPhiThroughItsBasis) {
  using M = TypeParam;
  this->for_states([&](const State<M>& s, const ParameterVector<M>& phi) {
    typename M::template InertiaBasis<double> basis;
    M::inertia_basis(s.q, basis);
    Eigen::Matrix<double, M::nq, M::nq> sum = basis.constant;
    for (int i = 0; i < M::np; ++i) sum += phi(i) * basis.linear[i];
    EXPECT_TRUE(close(M::inertia(s.q, phi), sum, kRelTol));
  });
}

TYPED_TEST(RobotModel, InertiaIsSymmetric) {
  using M = TypeParam;
  this->for_states([&](const State<M>& s, const ParameterVector<M>& phi) {
    const Eigen::Matrix<double, M::nq, M::nq> A = M::inertia(s.q, phi);
    EXPECT_TRUE(close(A, A.transpose(), kRelTol));
  });
}

TYPED_TEST(RobotModel, InertiaTimesQddPlusNonlinearEffectsIsInverseDynamics) {
  using M = TypeParam;
  this->for_states([&](const State<M>& s, const ParameterVector<M>& phi) {
    EXPECT_TRUE(close(M::inertia(s.q, phi) * s.qdd + M::nonlinear_effects(s.q, s.qd, phi),
                      M::inverse_dynamics(s.q, s.qd, s.qdd, phi), kRelTol));
  });
}

// The output-argument forms write into a block of a larger matrix and agree with the
// value-returning forms (the contract allows any writable Eigen expression). Both run the same
// arithmetic, so only contraction into fused multiply-adds may tell them apart.
TYPED_TEST(RobotModel, OutputFormsWriteBlocksOfLargerMatrices) {
  using M = TypeParam;
  constexpr int nq = M::nq, np = M::np;
  this->for_states([&](const State<M>& s, const ParameterVector<M>& phi) {
    const JointVector<M> tau = this->random_torque();
    // Every output fits in rows [2, 2 + nq + 6) and columns [3, 3 + nq + np + 4) of `big`.
    Eigen::MatrixXd big = Eigen::MatrixXd::Constant(nq + 16, nq + np + 16, 7.0);
    const auto at = [&](int rows, int cols) { return big.block(2, 3, rows, cols); };
    M::regressor(s.q, s.qd, s.qdd, at(nq, np));
    EXPECT_TRUE(close(at(nq, np), M::regressor(s.q, s.qd, s.qdd), kSameArithmetic)) << "regressor";
    M::fixed_torque(s.q, s.qd, s.qdd, at(nq, 1));
    EXPECT_TRUE(close(at(nq, 1), M::fixed_torque(s.q, s.qd, s.qdd), kSameArithmetic)) << "fixed_torque";
    M::inverse_dynamics(s.q, s.qd, s.qdd, phi, at(nq, 1));
    EXPECT_TRUE(close(at(nq, 1), M::inverse_dynamics(s.q, s.qd, s.qdd, phi), kSameArithmetic)) << "inverse_dynamics";
    M::inertia(s.q, phi, at(nq, nq));
    EXPECT_TRUE(close(at(nq, nq), M::inertia(s.q, phi), kSameArithmetic)) << "inertia";
    M::nonlinear_effects(s.q, s.qd, phi, at(nq, 1));
    EXPECT_TRUE(close(at(nq, 1), M::nonlinear_effects(s.q, s.qd, phi), kSameArithmetic)) << "nonlinear_effects";
    M::forward_dynamics(s.q, s.qd, tau, phi, at(nq, 1));
    EXPECT_TRUE(close(at(nq, 1), M::forward_dynamics(s.q, s.qd, tau, phi), kSameArithmetic)) << "forward_dynamics";
    M::forward_kinematics(s.q, at(4, 4));
    EXPECT_TRUE(close(at(4, 4), M::forward_kinematics(s.q), kSameArithmetic)) << "forward_kinematics";
    M::jacobian(s.q, at(6, nq));
    EXPECT_TRUE(close(at(6, nq), M::jacobian(s.q), kSameArithmetic)) << "jacobian";
    // Nothing outside the blocks was touched.
    big.block(2, 3, nq + 6, nq + np + 4).setConstant(7.0);
    EXPECT_TRUE((big.array() == 7.0).all()) << "an output form wrote outside its block";
  });
}

// ---- d. Forward dynamics -----------------------------------------------------------------------

TYPED_TEST(RobotModel, ForwardDynamicsSolvesInertiaAndInvertsInverseDynamics) {
  using M = TypeParam;
  this->for_states([&](const State<M>& s, const auto&) {
    const ParameterVector<M> phi = this->physical_phi();
    const JointVector<M> tau = this->random_torque();
    const JointVector<M> qdd = M::forward_dynamics(s.q, s.qd, tau, phi);
    const Eigen::Matrix<double, M::nq, M::nq> A = M::inertia(s.q, phi);
    const JointVector<M> h = M::nonlinear_effects(s.q, s.qd, phi);
    EXPECT_TRUE(close(qdd, A.partialPivLu().solve(tau - h), kRelTol));
    EXPECT_TRUE(close(M::inverse_dynamics(s.q, s.qd, qdd, phi), tau, kRelTol));
  });
}

// ---- e. Jet derivatives ------------------------------------------------------------------------

// The generated functions run in Jets (jet_support.hpp: one Jet type, a derivative along a random
// direction u of q, and every argument a Jet, so that each function has one Jet instantiation);
// the derivative part is the central-difference Jacobian of the double version times u. The
// forward kinematics here; the regressor, inverse dynamics, forward dynamics and inertia in the
// derivative units, which instantiate them in Jets anyway (test_robot_derivatives_*.cpp).
TYPED_TEST(RobotModel, JetDerivativeOfForwardKinematicsMatchesFiniteDifferences) {
  using M = TypeParam;
  this->for_states([&](const State<M>& s, const auto&) {
    const JointVector<M> u = this->random_direction();
    const auto T = M::forward_kinematics(jet(s.q, u));
    const Eigen::MatrixXd fd =
        finite_difference_jacobian([&](const JointVector<M>& x) { return M::forward_kinematics(x); }, s.q, kFdStep);
    EXPECT_TRUE(close(flat_derivative(T), fd * u, kFdTol));
    // The value part of the Jet evaluation is the double evaluation.
    EXPECT_TRUE(close(values(T), M::forward_kinematics(s.q), kRelTol));
  });
}

// The Jacobian is the derivative of the forward kinematics: along a random direction u of q, its
// linear rows give d p / d q u and its angular rows the axial vector of (d R / d q u) R^T.
TYPED_TEST(RobotModel, JacobianIsTheDerivativeOfForwardKinematics) {
  using M = TypeParam;
  this->for_states([&](const State<M>& s, const auto&) {
    const JointVector<M> u = this->random_direction();
    const auto T = M::forward_kinematics(jet(s.q, u));
    const Eigen::Matrix3d R = values(T.template topLeftCorner<3, 3>());
    const Eigen::MatrixXd dT = derivative(T);
    const Eigen::Matrix3d w = dT.topLeftCorner<3, 3>() * R.transpose();  // skew-symmetric
    Eigen::Matrix<double, 6, 1> expected;
    expected << dT(0, 3), dT(1, 3), dT(2, 3), w(2, 1), w(0, 2), w(1, 0);
    EXPECT_TRUE(close(M::jacobian(s.q) * u, expected, kRelTol));
  });
}

// ---- f. Independent Newton-Euler with standard parameters --------------------------------------

template <class Model>
Eigen::VectorXd newton_euler_torque(const std::vector<LinkInertia>& links, const State<Model>& s,
                                    bool with_gravity = true) {
  const Eigen::Vector3d g = with_gravity ? gravity_vector<Model>() : Eigen::Vector3d::Zero();
  return newton_euler(Model::frames, g, links, s.q, s.qd, s.qdd);
}

// For a variant the standard parameters are drawn so that the base parameters it fixes have
// their fixed values (standard_parameters_of_variant); the first check is that premise. The
// effect parameters (the last ne of s) add their hand-written terms to the Newton-Euler torque.
TYPED_TEST(RobotModel, NewtonEulerWithStandardParametersMatchesInverseDynamics) {
  using M = TypeParam;
  using Parent = typename M::Parent;
  this->for_states([&](const State<M>& s, const auto&) {
    const auto standard = standard_parameters_of_variant<M>(this->rng_);
    const ParameterVector<M> phi = M::base_from_standard(standard.s);
    const Eigen::Matrix<double, Parent::ns, 1> par_s = standard.s.template head<Parent::ns>();
    ASSERT_TRUE(close(M::to_parent(phi), Parent::base_from_standard(par_s), kRelTol));
    EXPECT_TRUE(close(M::inverse_dynamics(s.q, s.qd, s.qdd, phi),
                      newton_euler_torque<M>(standard.links, s) + effect_torque<M>(s.q, s.qd, standard.s),
                      kRelTol));
  });
}

// Column k of M is the Newton-Euler torque at rest without gravity for qdd = e_k (at rest the
// friction terms vanish too). With physical parameters (the full model) M is positive definite;
// a variant's zeroed entries need not leave the links physical.
TYPED_TEST(RobotModel, NewtonEulerColumnsGiveTheInertia) {
  using M = TypeParam;
  this->for_states([&](const State<M>& s, const auto&) {
    const auto standard = standard_parameters_of_variant<M>(this->rng_);
    Eigen::Matrix<double, M::nq, M::nq> expected;
    for (int k = 0; k < M::nq; ++k) {
      const State<M> unit{s.q, JointVector<M>::Zero(), JointVector<M>::Unit(k)};
      expected.col(k) = newton_euler_torque<M>(standard.links, unit, false);
    }
    const Eigen::Matrix<double, M::nq, M::nq> A = M::inertia(s.q, M::base_from_standard(standard.s));
    EXPECT_TRUE(close(A, expected, kRelTol));
    if constexpr (TestFixture::is_full) {
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A).eigenvalues().minCoeff(), 0.0);
    }
  });
}

// ---- g. Metadata -------------------------------------------------------------------------------

TYPED_TEST(RobotModel, ParameterMetadataIsWellFormed) {
  using M = TypeParam;
  static const std::set<std::string> families = {"XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX",  "MY", "MZ",
                                                 "M",  "IA", "FV", "FS", "OFF", "FST", "FVA", "HS", "HC", "FC"};
  std::set<std::string> seen;
  for (const auto& p : M::parameters) {
    SCOPED_TRACE(p.name);
    EXPECT_TRUE(seen.insert(p.name).second) << "duplicate parameter name";
    EXPECT_NE(std::string(p.unit), "");
    EXPECT_TRUE(families.count(p.family)) << p.family;
    EXPECT_GE(p.joint, 1);
    EXPECT_LE(p.joint, int(M::frames.size()));
  }
  EXPECT_EQ(int(M::parameters.size()), M::np);
  // Effect parameters are the last ne, in the order of effect_parameters, and nothing else is.
  constexpr int ne = effect_count<M>;
  for (int i = 0; i < M::np; ++i)
    EXPECT_EQ(is_effect_family(M::parameters[i].family), i >= M::np - ne) << M::parameters[i].name;
  if constexpr (ne > 0) {
    for (int k = 0; k < ne; ++k) {
      const auto& p = M::parameters[M::np - ne + k];
      const auto& e = M::effect_parameters[k];
      SCOPED_TRACE(e.name);
      EXPECT_EQ(std::string(p.name), e.name);
      EXPECT_EQ(std::string(p.family), e.family);
      EXPECT_EQ(p.joint, e.joint);
      EXPECT_LE(e.joint, M::nq);
      EXPECT_EQ(M::parent_index[M::np - ne + k], -1);
      const auto& sp = M::standard_parameters[M::ns - ne + k];
      EXPECT_EQ(std::string(sp.name), e.name);
      const std::string family = e.family;
      EXPECT_EQ(e.order >= 1, family == "HS" || family == "HC");
      EXPECT_EQ(e.velocity > 0, family == "FST" || family == "FC");
    }
  }
}

// The full model's parameters are exactly the columns of dim.txt and the parameter symbols of
// its tables; a variant's parameters and fixed parameters partition its robot's.
TYPED_TEST(RobotModel, ParametersAreTheBaseParametersOfTheFiles) {
  using M = TypeParam;
  using Parent = typename M::Parent;
  const auto names = parameter_names<M>();
  const std::set<std::string> mine(names.begin(), names.end());
  if constexpr (TestFixture::is_full) {
    const auto columns = this->ref().regressor_columns();
    const auto& symbols = this->ref().parameter_symbols();
    EXPECT_EQ(mine, std::set<std::string>(columns.begin(), columns.end()));
    EXPECT_EQ(mine, std::set<std::string>(symbols.begin(), symbols.end()));
    EXPECT_EQ(M::fixed_parameters.size(), 0u);
  } else {
    constexpr int ne = effect_count<M>;
    EXPECT_EQ(M::np - ne + int(M::fixed_parameters.size()), Parent::np);
    std::set<std::string> all(names.begin(), names.end() - ne);
    for (const auto& f : M::fixed_parameters) EXPECT_TRUE(all.insert(f.name).second) << f.name;
    const auto parent = parameter_names<Parent>();
    EXPECT_EQ(all, std::set<std::string>(parent.begin(), parent.end()));
  }
}

// to_parent fills the fixed values in and from_parent selects: a round trip is the identity
// (but for the effect parameters, which the full model lacks: they come back 0), and each
// parameter keeps its name.
TYPED_TEST(RobotModel, ToParentAndFromParentAreConsistent) {
  using M = TypeParam;
  using Parent = typename M::Parent;
  constexpr int ne = effect_count<M>;
  this->for_states([&](const State<M>&, const ParameterVector<M>& phi) {
    const Eigen::Matrix<double, Parent::np, 1> full = M::to_parent(phi);
    ParameterVector<M> expected = phi;
    expected.tail(ne).setZero();
    EXPECT_TRUE(close(M::from_parent(full), expected, 0.0));
    const ParameterValues by_name = parent_parameter_values<M>(phi);
    for (int i = 0; i < M::np - ne; ++i) EXPECT_EQ(by_name.at(M::parameters[i].name), phi(i));
    for (int i = M::np - ne; i < M::np; ++i) EXPECT_EQ(by_name.count(M::parameters[i].name), 0u);
    for (const auto& f : M::fixed_parameters) EXPECT_EQ(by_name.at(f.name), f.value) << f.name;
  });
}

TYPED_TEST(RobotModel, JointsMatchTheGeometryTable) {
  using M = TypeParam;
  const Reference& ref = this->ref();
  ASSERT_EQ(M::nq, ref.nq());
  int k = 0;
  for (const auto& f : M::frames) {
    if (f.sigma == 2) continue;
    const auto& joint = M::joints[k++];
    SCOPED_TRACE(joint.name);
    EXPECT_EQ(int(joint.type), f.sigma);
    EXPECT_TRUE(std::isfinite(joint.lower) && std::isfinite(joint.upper));
    EXPECT_LT(joint.lower, joint.upper);
    EXPECT_LE(joint.audit_lower, joint.audit_upper);
    EXPECT_GT(joint.velocity, 0.0);
    EXPECT_GT(joint.effort, 0.0);
  }
  EXPECT_EQ(k, M::nq);
}

// Model::frames is the geometry table with the constants of robot.yaml and q = 0.
TYPED_TEST(RobotModel, FramesAreTheGeometryTableEvaluated) {
  using M = TypeParam;
  const Reference& ref = this->ref();
  const grammar::Table& table = ref.geometry();
  ASSERT_EQ(M::frames.size(), table.rows.size());
  const std::vector<std::string> columns = {"ant", "sigma", "mu",    "gamma", "b",
                                            "alpha", "d",   "theta", "r"};
  for (std::size_t j = 0; j < table.rows.size(); ++j) {
    const FrameInfo& f = M::frames[j];
    const Eigen::Matrix<double, 9, 1> generated(f.ant, f.sigma, f.mu, f.gamma, f.b, f.alpha, f.d,
                                                f.theta, f.r);
    Eigen::Matrix<double, 9, 1> expected;
    for (int c = 0; c < 9; ++c) {
      const auto at = std::find(table.columns.begin(), table.columns.end(), columns[c]);
      ASSERT_NE(at, table.columns.end()) << columns[c];
      expected(c) = ref.constant_value(table.rows[j].cells[at - table.columns.begin()]);
    }
    EXPECT_TRUE(close(generated, expected, 1e-15, columns)) << "frame " << j + 1;
  }
}

// Gravity and the standard parameters come from the robot's .par: G, and the symbolic entries
// link by link, family by family (a variant may drop some, keeping the order).
TYPED_TEST(RobotModel, GravityAndStandardParametersFollowThePar) {
  using M = TypeParam;
  const grammar::ParFile par = grammar::read_par_file(par_file_path(SYMORO_ROBOT_DIR));
  const auto entry = [&](const std::string& name) -> const grammar::ParEntry& {
    for (const auto& e : par.entries)
      if (e.name == name) return e;
    throw std::runtime_error(par.path + ": no entry " + name);
  };
  const auto& G = entry("G").values;
  ASSERT_EQ(G.size(), 3u);
  const Eigen::Vector3d g(this->ref().constant_value(G[0]), this->ref().constant_value(G[1]),
                          this->ref().constant_value(G[2]));
  EXPECT_TRUE(close(gravity_vector<M>(), g, 1e-15));

  // "name family joint" of each symbolic entry of the .par.
  std::vector<std::string> expected;
  const char* families[] = {"XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M", "IA", "FV", "FS"};
  for (std::size_t j = 0; j < M::frames.size(); ++j)
    for (const char* family : families) {
      const grammar::Expr& e = entry(family).values.at(j);
      if (e.kind == grammar::Expr::Kind::Symbol)
        expected.push_back(e.name + " " + family + " " + std::to_string(j + 1));
    }
  // The effect parameters of a variant follow (the last ne; checked with the metadata).
  std::vector<std::string> listed;
  for (int k = 0; k < par_standard_count<M>; ++k) {
    const auto& p = M::standard_parameters[k];
    listed.push_back(std::string(p.name) + " " + p.family + " " + std::to_string(p.joint));
  }
  EXPECT_EQ(int(listed.size()), M::ns - effect_count<M>);
  if constexpr (TestFixture::is_full) {
    EXPECT_EQ(listed, expected);
  } else {
    // An ordered subsequence of the .par's list.
    auto from = expected.begin();
    for (const auto& name : listed) {
      from = std::find(from, expected.end(), name);
      EXPECT_NE(from, expected.end()) << name << " is not in the .par, or out of order";
    }
  }
}

}  // namespace
}  // namespace symoro::test
