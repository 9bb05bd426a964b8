// What only a template can check of one generated robot and all its variants
// (symoro::<robot>::Models), for the small shipped robots (tests/CMakeLists.txt): the header-only
// API that applications link statically (find_package(symoro), symoro::<robot>) in fixed sizes,
// into blocks of larger matrices and in Jets, and its inverse dynamics against an independent
// Newton-Euler. Every value of every robot folder against OpenSYMORO's files, Newton-Euler and
// central differences is test_robot_values.cpp's, through the robot library: the same generated
// templates instantiated in doubles (robot_abi_export-inl.hpp), compiled once. Built once per
// robot folder with SYMORO_ROBOT_HEADER, SYMORO_ROBOT_NS and SYMORO_ROBOT_DIR; nothing here
// names a robot.
#include SYMORO_ROBOT_HEADER

#include <string>
#include <type_traits>

#include <gtest/gtest.h>

#include "jet_support.hpp"
#include "newton_euler.hpp"
#include "robot_models.hpp"
#include "test_support.hpp"

namespace symoro::test {
namespace {

// Newton-Euler and the generated code evaluate the same expressions in a different order: 1e-9
// of the object's magnitude leaves room for that round-off (about 1e-13 to 1e-15 in practice).
constexpr double kRelTol = 1e-9;
// Central differences: kFdStep, kFdTol and kStates (test_support.hpp).
constexpr double kSameArithmetic = 1e-14;

template <class Model>
class RobotModel : public ::testing::Test {
 protected:
  // Calls check(state, phi) at kStates random states with order-1 random phi.
  template <class Check>
  void for_states(const Check& check) {
    for (int k = 0; k < kStates; ++k) {
      SCOPED_TRACE("random state " + std::to_string(k));
      const State<Model> s = random_state<Model>(rng_);
      check(s, random_phi<Model>(rng_));
    }
  }
  JointVector<Model> random_torque() { return rng_.vector<JointVector<Model>>(Model::nq, -5, 5); }
  // A random direction of q for the Jet checks, entries in [-1, 1], from a generator of its own:
  // the states and parameters stay those drawn from rng_.
  JointVector<Model> random_direction() { return direction_rng_.vector<JointVector<Model>>(Model::nq, -1, 1); }

  Random rng_{20240611};
  Random direction_rng_{20240612};
};
TYPED_TEST_SUITE(RobotModel, Models, ModelName);

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

// ---- Jet derivatives ----------------------------------------------------------------------------

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

// ---- Independent Newton-Euler with standard parameters -----------------------------------------

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
                      newton_euler_torque<M>(standard.links, s) + effect_torque<M>(s.q, s.qd, standard.s), kRelTol));
  });
}

}  // namespace
}  // namespace symoro::test
