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
  constexpr int nq = M::nq;
  this->for_states([&](const State<M>& s, const ParameterVector<M>& phi) {
    typename M::template InverseDynamicsDerivatives<double> d;
    M::inverse_dynamics_derivatives(s.q, s.qd, s.qdd, phi, d);
    EXPECT_TRUE(close(d.tau, M::inverse_dynamics(s.q, s.qd, s.qdd, phi), 1e-12)) << "tau";
    EXPECT_TRUE(close(d.dq, jet_jacobian(M::inverse_dynamics(seeded<nq>(s.q), s.qd, s.qdd, phi)), kJetTol)) << "d tau / d q";
    EXPECT_TRUE(close(d.dqd, jet_jacobian(M::inverse_dynamics(s.q, seeded<nq>(s.qd), s.qdd, phi)), kJetTol)) << "d tau / d qd";
    EXPECT_TRUE(close(d.dq, finite_difference_jacobian([&](const JointVector<M>& x) { return M::inverse_dynamics(x, s.qd, s.qdd, phi); },
                                                       s.q, kFdStep),
                      kFdTol))
        << "d tau / d q, finite differences";
    EXPECT_TRUE(close(d.dqd, finite_difference_jacobian([&](const JointVector<M>& x) { return M::inverse_dynamics(s.q, x, s.qdd, phi); },
                                                        s.qd, kFdStep),
                      kFdTol))
        << "d tau / d qd, finite differences";
  });
}

}  // namespace
}  // namespace symoro::test
