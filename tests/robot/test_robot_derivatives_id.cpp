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
    // The Jet reference along random directions u, w: d tau / d q u and d tau / d qd w.
    const auto u = this->template random_direction<JointVector<M>>();
    const auto w = this->template random_direction<JointVector<M>>();
    EXPECT_TRUE(close(d.dq * u, derivative(M::inverse_dynamics(jet(s.q, u), jet(s.qd), jet(s.qdd), jet(phi))), kJetTol))
        << "d tau / d q along u";
    EXPECT_TRUE(close(d.dqd * w, derivative(M::inverse_dynamics(jet(s.q), jet(s.qd, w), jet(s.qdd), jet(phi))), kJetTol))
        << "d tau / d qd along w";
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
