// The generated derivative functions of one robot and all its variants run in Jets (second derivatives).
// Against two independent references: forward-mode ceres::Jet through the generated value
// functions, and central finite differences of their double versions (derivatives_support.hpp).
#include "derivatives_support.hpp"

namespace symoro::test {
namespace {

template <class Model>
class DerivativeFunctionsInJets : public RobotDerivatives<Model> {};
TYPED_TEST_SUITE(DerivativeFunctionsInJets, Models, ModelName);

// The derivative functions are templated on the scalar too: in Jets they give second
// derivatives, here d/dq of d tau / d qd, against finite differences of the double version.
TYPED_TEST(DerivativeFunctionsInJets, DerivativeFunctionsRunInJets) {
  using M = TypeParam;
  constexpr int nq = M::nq;
  using Jet = ceres::Jet<double, nq>;
  this->for_states([&](const State<M>& s, const ParameterVector<M>& phi) {
    typename M::template InverseDynamicsDerivatives<Jet> dj;
    M::inverse_dynamics_derivatives(seeded<nq>(s.q), s.qd, s.qdd, phi, dj);
    typename M::template InverseDynamicsDerivatives<double> d;
    M::inverse_dynamics_derivatives(s.q, s.qd, s.qdd, phi, d);
    EXPECT_TRUE(close(values(dj.dqd), d.dqd, 1e-12));
    const Eigen::MatrixXd second = finite_difference_jacobian(
        [&](const JointVector<M>& x) {
          typename M::template InverseDynamicsDerivatives<double> e;
          M::inverse_dynamics_derivatives(x, s.qd, s.qdd, phi, e);
          return Eigen::Matrix<double, nq, nq>(e.dqd);
        },
        s.q, kFdStep);
    EXPECT_TRUE(close(jet_jacobian(dj.dqd), second, kFdTol)) << "d^2 tau / d q d qd";
  });
}

}  // namespace
}  // namespace symoro::test
