// The generated forward dynamics derivatives of one robot and all its variants (issue 16), and their refusal of an indefinite inertia.
// Against two independent references: forward-mode ceres::Jet through the generated value
// functions, and central finite differences of their double versions (derivatives_support.hpp).
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "derivatives_support.hpp"

namespace symoro::test {
namespace {

template <class Model>
class ForwardDynamicsDerivatives : public RobotDerivatives<Model> {};
TYPED_TEST_SUITE(ForwardDynamicsDerivatives, Models, ModelName);

// Two evaluations of qdd in a different order of operations: 1e-9 of its magnitude (round-off
// times the conditioning of M; test_robot.cpp's kRelTol).
constexpr double kSameValue = 1e-9;

TYPED_TEST(ForwardDynamicsDerivatives, ForwardDynamicsDerivativesAreTheJetAndFiniteDifferenceDerivatives) {
  using M = TypeParam;
  this->for_states([&](const State<M>& s, const ParameterVector<M>&) {
    const ParameterVector<M> phi = this->physical_phi();
    const JointVector<M> tau = this->random_torque();
    typename M::template ForwardDynamicsDerivatives<double> d;
    ASSERT_TRUE(M::forward_dynamics_derivatives(s.q, s.qd, tau, phi, d));
    EXPECT_GT(d.min_pivot, 0);
    // The value: ddm.txt's forward dynamics, which the generated code evaluates another way.
    EXPECT_TRUE(close(d.qdd, M::forward_dynamics(s.q, s.qd, tau, phi), kSameValue)) << "qdd";
    const auto fd = [&](const auto& f, const auto& x) { return finite_difference_jacobian(f, x, kFdStep); };
    const Eigen::MatrixXd fd_q =
        fd([&](const JointVector<M>& x) { return M::forward_dynamics(x, s.qd, tau, phi); }, s.q);
    const Eigen::MatrixXd fd_qd =
        fd([&](const JointVector<M>& x) { return M::forward_dynamics(s.q, x, tau, phi); }, s.qd);
    const Eigen::MatrixXd fd_phi =
        fd([&](const ParameterVector<M>& x) { return M::forward_dynamics(s.q, s.qd, tau, x); }, phi);
    EXPECT_TRUE(close(d.dq, fd_q, kFdTol)) << "d qdd / d q, finite differences";
    EXPECT_TRUE(close(d.dqd, fd_qd, kFdTol)) << "d qdd / d qd, finite differences";
    EXPECT_TRUE(close(d.dphi, fd_phi, kFdTol)) << "d qdd / d phi, finite differences";
    // d qdd / d tau = M^-1 and d qdd / d phi = -M^-1 W(q, qd, qdd), from the other generated functions.
    const Eigen::Matrix<double, M::nq, M::nq> Minv = M::inertia(s.q, phi).inverse();
    EXPECT_TRUE(close(d.dtau, Minv, kJetTol)) << "M^-1";
    EXPECT_TRUE(close(d.dphi, -Minv * M::regressor(s.q, s.qd, d.qdd), kJetTol)) << "-M^-1 W";
    // The Jet reference along a random direction of each argument (one Jet instantiation of
    // forward_dynamics: jet_support.hpp). Along u also against the central differences, and the
    // value part against the double evaluation (formerly in test_robot.cpp).
    const auto u = this->template random_direction<JointVector<M>>();
    const auto w = this->template random_direction<JointVector<M>>();
    const auto t = this->template random_direction<JointVector<M>>();
    const auto p = this->template random_direction<ParameterVector<M>>();
    const auto along_u = M::forward_dynamics(jet(s.q, u), jet(s.qd), jet(tau), jet(phi));
    EXPECT_TRUE(close(d.dq * u, derivative(along_u), kJetTol)) << "d qdd / d q along u";
    EXPECT_TRUE(close(derivative(along_u), fd_q * u, kFdTol)) << "d qdd / d q along u: Jet and finite differences";
    EXPECT_TRUE(close(values(along_u), M::forward_dynamics(s.q, s.qd, tau, phi), kSameValue)) << "qdd in Jets";
    EXPECT_TRUE(close(d.dqd * w, derivative(M::forward_dynamics(jet(s.q), jet(s.qd, w), jet(tau), jet(phi))), kJetTol))
        << "d qdd / d qd along w";
    EXPECT_TRUE(close(d.dtau * t, derivative(M::forward_dynamics(jet(s.q), jet(s.qd), jet(tau, t), jet(phi))), kJetTol))
        << "d qdd / d tau along t";
    EXPECT_TRUE(close(d.dphi * p, derivative(M::forward_dynamics(jet(s.q), jet(s.qd), jet(tau), jet(phi, p))), kJetTol))
        << "d qdd / d phi along p";
  });
}

// An inertia matrix that is not positive definite is reported, not inverted.
TYPED_TEST(ForwardDynamicsDerivatives, ForwardDynamicsDerivativesRefuseAnIndefiniteInertia) {
  using M = TypeParam;
  this->for_states([&](const State<M>& s, const ParameterVector<M>&) {
    const ParameterVector<M> phi = -this->physical_phi();  // M(q; -phi) = -M(q; phi) + constant part
    const Eigen::Matrix<double, M::nq, M::nq> A = M::inertia(s.q, phi);
    const double smallest =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, M::nq, M::nq>>(A).eigenvalues().minCoeff();
    typename M::template ForwardDynamicsDerivatives<double> d;
    const bool ok = M::forward_dynamics_derivatives(s.q, s.qd, this->random_torque(), phi, d);
    EXPECT_EQ(ok, smallest > 0) << "smallest eigenvalue of M " << smallest << ", smallest pivot " << d.min_pivot;
  });
}

}  // namespace
}  // namespace symoro::test
