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
// derivatives. Here inverse_dynamics_derivatives in Jets along a random direction of q, then of qd
// (one Jet instantiation: jet_support.hpp): the value part is the double evaluation, the derivative
// part of tau the generated first derivative along it, and those of d tau / d q and d tau / d qd
// the central differences of the double version along it.
TYPED_TEST(DerivativeFunctionsInJets, DerivativeFunctionsRunInJets) {
  using M = TypeParam;
  constexpr int nq = M::nq;
  using Mat = Eigen::Matrix<double, nq, nq>;
  this->for_states([&](const State<M>& s, const ParameterVector<M>& phi) {
    typename M::template InverseDynamicsDerivatives<double> d;
    M::inverse_dynamics_derivatives(s.q, s.qd, s.qdd, phi, d);
    // d tau / d q and d tau / d qd side by side, as functions of q or of qd: central differences.
    const auto both = [&](const JointVector<M>& q, const JointVector<M>& qd) {
      typename M::template InverseDynamicsDerivatives<double> e;
      M::inverse_dynamics_derivatives(q, qd, s.qdd, phi, e);
      Eigen::Matrix<double, nq, 2 * nq> out;
      out << e.dq, e.dqd;
      return out;
    };
    const Eigen::MatrixXd in_q =
        finite_difference_jacobian([&](const JointVector<M>& x) { return both(x, s.qd); }, s.q, kFdStep);
    const Eigen::MatrixXd in_qd =
        finite_difference_jacobian([&](const JointVector<M>& x) { return both(s.q, x); }, s.qd, kFdStep);
    const auto u = this->template random_direction<JointVector<M>>();
    const auto w = this->template random_direction<JointVector<M>>();
    for (const bool along_q : {true, false}) {
      SCOPED_TRACE(along_q ? "along a direction of q" : "along a direction of qd");
      const JointVector<M>& v = along_q ? u : w;
      typename M::template InverseDynamicsDerivatives<Dual> dj;
      if (along_q)
        M::inverse_dynamics_derivatives(jet(s.q, v), jet(s.qd), jet(s.qdd), jet(phi), dj);
      else
        M::inverse_dynamics_derivatives(jet(s.q), jet(s.qd, v), jet(s.qdd), jet(phi), dj);
      EXPECT_TRUE(close(values(dj.tau), d.tau, 1e-12)) << "tau";
      EXPECT_TRUE(close(values(dj.dq), d.dq, 1e-12)) << "d tau / d q";
      EXPECT_TRUE(close(values(dj.dqd), d.dqd, 1e-12)) << "d tau / d qd";
      EXPECT_TRUE(close(derivative(dj.tau), (along_q ? d.dq : d.dqd) * v, kJetTol)) << "d tau along v";
      const Eigen::VectorXd second = (along_q ? in_q : in_qd) * v;
      EXPECT_TRUE(close(derivative(dj.dq), Eigen::Map<const Mat>(second.data()), kFdTol)) << "d^2 tau / d q along v";
      EXPECT_TRUE(close(derivative(dj.dqd), Eigen::Map<const Mat>(second.data() + nq * nq), kFdTol))
          << "d^2 tau / d qd along v";
    }
  });
}

}  // namespace
}  // namespace symoro::test
