// The generated inverse dynamics derivatives of one robot and all its variants (issue 16).
// Against two independent references: forward-mode ceres::Jet through the generated value
// functions, and central finite differences of their double versions (derivatives_support.hpp).
#include "derivatives_support.hpp"

namespace symoro::test {
namespace {

template <class Model>
class InverseDynamicsDerivatives : public RobotDerivatives<Model> {};
TYPED_TEST_SUITE(InverseDynamicsDerivatives, Models, ModelName);

TYPED_TEST(InverseDynamicsDerivatives, InverseDynamicsDerivativesAreTheJetAndFiniteDifferenceDerivatives) {
  using M = TypeParam;
  this->for_states([&](const State<M>& s, const ParameterVector<M>& phi) {
    typename M::template InverseDynamicsDerivatives<double> d;
    M::inverse_dynamics_derivatives(s.q, s.qd, s.qdd, phi, d);
    EXPECT_TRUE(close(d.tau, M::inverse_dynamics(s.q, s.qd, s.qdd, phi), 1e-12)) << "tau";
    const Eigen::MatrixXd fd_q = finite_difference_jacobian(
        [&](const JointVector<M>& x) { return M::inverse_dynamics(x, s.qd, s.qdd, phi); }, s.q, kFdStep);
    const Eigen::MatrixXd fd_qd = finite_difference_jacobian(
        [&](const JointVector<M>& x) { return M::inverse_dynamics(s.q, x, s.qdd, phi); }, s.qd, kFdStep);
    EXPECT_TRUE(close(d.dq, fd_q, kFdTol)) << "d tau / d q, finite differences";
    EXPECT_TRUE(close(d.dqd, fd_qd, kFdTol)) << "d tau / d qd, finite differences";
    // The Jet reference along random directions u, w: d tau / d q u and d tau / d qd w. The
    // inverse dynamics in Jets against the central differences too (formerly in test_robot.cpp).
    const auto u = this->template random_direction<JointVector<M>>();
    const auto w = this->template random_direction<JointVector<M>>();
    const auto along_u = M::inverse_dynamics(jet(s.q, u), jet(s.qd), jet(s.qdd), jet(phi));
    EXPECT_TRUE(close(d.dq * u, derivative(along_u), kJetTol)) << "d tau / d q along u";
    EXPECT_TRUE(close(derivative(along_u), fd_q * u, kFdTol)) << "d tau / d q along u: Jet and finite differences";
    EXPECT_TRUE(close(values(along_u), d.tau, 1e-12)) << "tau in Jets";
    const auto along_w = M::inverse_dynamics(jet(s.q), jet(s.qd, w), jet(s.qdd), jet(phi));
    EXPECT_TRUE(close(d.dqd * w, derivative(along_w), kJetTol)) << "d tau / d qd along w";
  });
}

// The regressor runs in Jets: along a random direction u of q its derivative part is the central
// differences of the double version times u (formerly in test_robot.cpp).
TYPED_TEST(InverseDynamicsDerivatives, JetDerivativeOfRegressorInQMatchesFiniteDifferences) {
  using M = TypeParam;
  this->for_states([&](const State<M>& s, const ParameterVector<M>&) {
    const auto u = this->template random_direction<JointVector<M>>();
    const Eigen::MatrixXd fd =
        finite_difference_jacobian([&](const JointVector<M>& x) { return M::regressor(x, s.qd, s.qdd); }, s.q, kFdStep);
    EXPECT_TRUE(close(flat_derivative(M::regressor(jet(s.q, u), jet(s.qd), jet(s.qdd))), fd * u, kFdTol));
  });
}

// tau is linear in phi, so its Jet derivative along a random direction p of phi is the regressor
// times p, to round-off (formerly in test_robot.cpp).
TYPED_TEST(InverseDynamicsDerivatives, JetDerivativeOfInverseDynamicsInPhiIsRegressor) {
  using M = TypeParam;
  this->for_states([&](const State<M>& s, const ParameterVector<M>& phi) {
    const auto p = this->template random_direction<ParameterVector<M>>();
    const auto tau = M::inverse_dynamics(jet(s.q), jet(s.qd), jet(s.qdd), jet(phi, p));
    EXPECT_TRUE(close(derivative(tau), M::regressor(s.q, s.qd, s.qdd) * p, 1e-12));
  });
}

}  // namespace
}  // namespace symoro::test
