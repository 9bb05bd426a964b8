// The generated inertia derivatives of one robot and all its variants (issue 16).
// Against two independent references: forward-mode ceres::Jet through the generated value
// functions, and central finite differences of their double versions (derivatives_support.hpp).
#include "derivatives_support.hpp"

namespace symoro::test {
namespace {

template <class Model>
class InertiaDerivatives : public RobotDerivatives<Model> {};
TYPED_TEST_SUITE(InertiaDerivatives, Models, ModelName);

// d M / d q_k from the generated inertia_derivatives, against the Jet derivative of inertia() and
// central differences; in Jets it gives d2 M / d q_k d q_l, against differences of itself.
TYPED_TEST(InertiaDerivatives, InertiaDerivativesAreTheJetAndFiniteDifferenceDerivatives) {
  using M = TypeParam;
  constexpr int nq = M::nq;
  using Mat = Eigen::Matrix<double, nq, nq>;
  this->for_states([&](const State<M>& s, const ParameterVector<M>& phi) {
    typename M::template InertiaDerivatives<double> d;
    M::inertia_derivatives(s.q, phi, d);
    EXPECT_TRUE(close(d.M, M::inertia(s.q, phi), 1e-12)) << "M";
    const auto jet = M::inertia(seeded<nq>(s.q), phi);
    const Eigen::MatrixXd fd =
        finite_difference_jacobian([&](const JointVector<M>& x) { return Mat(M::inertia(x, phi)); }, s.q, kFdStep);
    for (int k = 0; k < nq; ++k) {
      SCOPED_TRACE("d M / d q_" + std::to_string(k + 1));
      Mat from_jet, from_fd;
      for (int i = 0; i < nq; ++i)
        for (int j = 0; j < nq; ++j) {
          from_jet(i, j) = jet(i, j).v(k);
          from_fd(i, j) = fd(j * nq + i, k);
        }
      EXPECT_TRUE(close(d.dq[k], from_jet, kJetTol));
      EXPECT_TRUE(close(d.dq[k], from_fd, kFdTol));
    }
    using Jet = ceres::Jet<double, nq>;
    typename M::template InertiaDerivatives<Jet> dj;
    M::inertia_derivatives(seeded<nq>(s.q), phi, dj);
    const int k = nq - 1;  // d/dq of d M / d q_k for one k
    const Eigen::MatrixXd second = finite_difference_jacobian(
        [&](const JointVector<M>& x) {
          typename M::template InertiaDerivatives<double> e;
          M::inertia_derivatives(x, phi, e);
          return Mat(e.dq[k]);
        },
        s.q, kFdStep);
    EXPECT_TRUE(close(jet_jacobian(dj.dq[k]), second, kFdTol)) << "d2 M / d q d q_" << k + 1;
  });
}

}  // namespace
}  // namespace symoro::test
