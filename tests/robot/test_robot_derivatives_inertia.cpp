// The generated inertia derivatives of one robot and all its variants (issue 16).
// Against two independent references: forward-mode ceres::Jet through the generated value
// functions, and central finite differences of their double versions (derivatives_support.hpp).
#include "derivatives_support.hpp"

namespace symoro::test {
namespace {

template <class Model>
class InertiaDerivatives : public RobotDerivatives<Model> {};
TYPED_TEST_SUITE(InertiaDerivatives, Models, ModelName);

// d M / d q_k from the generated inertia_derivatives, against central differences of inertia() and,
// along a random direction u, the Jet derivative of inertia() (itself against the differences); in Jets along u it gives
// sum_l d2 M / d q_k d q_l u_l for every k, against central differences of itself.
TYPED_TEST(InertiaDerivatives, InertiaDerivativesAreTheJetAndFiniteDifferenceDerivatives) {
  using M = TypeParam;
  constexpr int nq = M::nq;
  using Mat = Eigen::Matrix<double, nq, nq>;
  this->for_states([&](const State<M>& s, const ParameterVector<M>& phi) {
    typename M::template InertiaDerivatives<double> d;
    M::inertia_derivatives(s.q, phi, d);
    EXPECT_TRUE(close(d.M, M::inertia(s.q, phi), 1e-12)) << "M";
    const Eigen::MatrixXd fd =
        finite_difference_jacobian([&](const JointVector<M>& x) { return Mat(M::inertia(x, phi)); }, s.q, kFdStep);
    for (int k = 0; k < nq; ++k) {
      SCOPED_TRACE("d M / d q_" + std::to_string(k + 1));
      const Mat from_fd = Eigen::Map<const Mat>(fd.col(k).data());
      EXPECT_TRUE(close(d.dq[k], from_fd, kFdTol));
    }
    // Along u: sum_k u_k d M / d q_k, the derivative part of inertia() in Jets along u.
    const auto u = this->template random_direction<JointVector<M>>();
    Mat along_u = Mat::Zero();
    for (int k = 0; k < nq; ++k) along_u += u(k) * d.dq[k];
    const auto M_along_u = M::inertia(jet(s.q, u), jet(phi));
    EXPECT_TRUE(close(along_u, derivative(M_along_u), kJetTol)) << "d M / d q along u";
    // inertia() in Jets against the central differences too (formerly in test_robot.cpp).
    EXPECT_TRUE(close(flat_derivative(M_along_u), fd * u, kFdTol)) << "d M / d q along u: Jet and finite differences";

    // inertia_derivatives in Jets along u: its value part is the double evaluation, the
    // derivative part of M is along_u, and that of d M / d q_k the second derivatives along u.
    typename M::template InertiaDerivatives<Dual> dj;
    M::inertia_derivatives(jet(s.q, u), jet(phi), dj);
    EXPECT_TRUE(close(values(dj.M), d.M, 1e-12)) << "M in Jets";
    EXPECT_TRUE(close(derivative(dj.M), along_u, kJetTol)) << "d M / d q along u, from inertia_derivatives in Jets";
    // Central differences of all of d M / d q_k at once: rows k nq^2 .. (k + 1) nq^2 - 1 are vec(d M / d q_k).
    const Eigen::MatrixXd second = finite_difference_jacobian(
        [&](const JointVector<M>& x) {
          typename M::template InertiaDerivatives<double> e;
          M::inertia_derivatives(x, phi, e);
          Eigen::Matrix<double, nq * nq, nq> all;
          for (int k = 0; k < nq; ++k) all.col(k) = Eigen::Map<const Eigen::Matrix<double, nq * nq, 1>>(e.dq[k].data());
          return all;
        },
        s.q, kFdStep);
    const Eigen::VectorXd second_u = second * u;
    for (int k = 0; k < nq; ++k) {
      const Mat expected = Eigen::Map<const Mat>(second_u.data() + k * nq * nq);
      EXPECT_TRUE(close(derivative(dj.dq[k]), expected, kFdTol)) << "d2 M / d q d q_" << k + 1 << " along u";
    }
  });
}

}  // namespace
}  // namespace symoro::test
