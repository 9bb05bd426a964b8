// The generated derivatives of one robot and all its variants (issue 16), against two independent
// references: forward-mode ceres::Jet through the generated value functions, and central finite
// differences of their double versions. Built into test_robot_<robot> with test_robot.cpp.
#include SYMORO_ROBOT_HEADER

#include <string>
#include <tuple>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <gtest/gtest.h>

#include "jet_support.hpp"
#include "test_support.hpp"

namespace symoro::test {
namespace {

template <class Tuple>
struct AsTypes;
template <class... Model>
struct AsTypes<std::tuple<Model...>> {
  using type = ::testing::Types<Model...>;
};
using Models = AsTypes<SYMORO_ROBOT_NS::Models>::type;

struct ModelName {
  template <class Model>
  static std::string GetName(int) {
    const std::string variant = Model::variant_name;
    return variant.empty() ? "full" : variant;
  }
};

// Generated derivative vs Jet derivative of the generated value: the same exact derivative in a
// different order of operations; 1e-10 of the object's magnitude (round-off, times the
// conditioning of M for the forward dynamics).
constexpr double kJetTol = 1e-10;
// Central differences with h = 1e-6: truncation ~h^2, round-off ~1e-16/h.
constexpr double kFdStep = 1e-6;
constexpr double kFdTol = 1e-6;
constexpr int kStates = 5;

template <class Model>
class RobotDerivatives : public ::testing::Test {
 protected:
  template <class Check>
  void for_states(const Check& check) {
    for (int k = 0; k < kStates; ++k) {
      SCOPED_TRACE("random state " + std::to_string(k));
      const State<Model> s = random_state<Model>(rng_);
      check(s, random_phi<Model>(rng_));
    }
  }
  // phi of physical standard parameters: M positive definite (see test_robot.cpp).
  ParameterVector<Model> physical_phi() { return Model::base_from_standard(random_standard_parameters<Model>(rng_).s); }
  JointVector<Model> random_torque() { return rng_.vector<JointVector<Model>>(Model::nq, -5, 5); }

  Random rng_{20261124};
};
TYPED_TEST_SUITE(RobotDerivatives, Models, ModelName);

TYPED_TEST(RobotDerivatives, InverseDynamicsDerivativesAreTheJetAndFiniteDifferenceDerivatives) {
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

TYPED_TEST(RobotDerivatives, ForwardDynamicsDerivativesAreTheJetAndFiniteDifferenceDerivatives) {
  using M = TypeParam;
  constexpr int nq = M::nq;
  this->for_states([&](const State<M>& s, const ParameterVector<M>&) {
    const ParameterVector<M> phi = this->physical_phi();
    const JointVector<M> tau = this->random_torque();
    typename M::template ForwardDynamicsDerivatives<double> d;
    ASSERT_TRUE(M::forward_dynamics_derivatives(s.q, s.qd, tau, phi, d));
    EXPECT_GT(d.min_pivot, 0);
    // The value: ddm.txt's forward dynamics, which the generated code evaluates another way.
    EXPECT_TRUE(close(d.qdd, M::forward_dynamics(s.q, s.qd, tau, phi), 1e-9)) << "qdd";
    EXPECT_TRUE(close(d.dq, jet_jacobian(M::forward_dynamics(seeded<nq>(s.q), s.qd, tau, phi)), kJetTol)) << "d qdd / d q";
    EXPECT_TRUE(close(d.dqd, jet_jacobian(M::forward_dynamics(s.q, seeded<nq>(s.qd), tau, phi)), kJetTol)) << "d qdd / d qd";
    EXPECT_TRUE(close(d.dtau, jet_jacobian(M::forward_dynamics(s.q, s.qd, seeded<nq>(tau), phi)), kJetTol)) << "d qdd / d tau";
    EXPECT_TRUE(close(d.dphi, jet_jacobian(M::forward_dynamics(s.q, s.qd, tau, seeded<M::np>(phi))), kJetTol)) << "d qdd / d phi";
    // d qdd / d tau = M^-1 and d qdd / d phi = -M^-1 W(q, qd, qdd), from the other generated functions.
    const Eigen::Matrix<double, nq, nq> Minv = M::inertia(s.q, phi).inverse();
    EXPECT_TRUE(close(d.dtau, Minv, kJetTol)) << "M^-1";
    EXPECT_TRUE(close(d.dphi, -Minv * M::regressor(s.q, s.qd, d.qdd), kJetTol)) << "-M^-1 W";
    const auto fd = [&](const auto& f, const auto& x) { return finite_difference_jacobian(f, x, kFdStep); };
    EXPECT_TRUE(close(d.dq, fd([&](const JointVector<M>& x) { return M::forward_dynamics(x, s.qd, tau, phi); }, s.q), kFdTol))
        << "d qdd / d q, finite differences";
    EXPECT_TRUE(close(d.dqd, fd([&](const JointVector<M>& x) { return M::forward_dynamics(s.q, x, tau, phi); }, s.qd), kFdTol))
        << "d qdd / d qd, finite differences";
    EXPECT_TRUE(close(d.dphi, fd([&](const ParameterVector<M>& x) { return M::forward_dynamics(s.q, s.qd, tau, x); }, phi), kFdTol))
        << "d qdd / d phi, finite differences";
  });
}

// The derivative functions are templated on the scalar too: in Jets they give second
// derivatives, here d/dq of d tau / d qd, against finite differences of the double version.
TYPED_TEST(RobotDerivatives, DerivativeFunctionsRunInJets) {
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

// d M / d q_k from the generated inertia_derivatives, against the Jet derivative of inertia() and
// central differences; in Jets it gives d2 M / d q_k d q_l, against differences of itself.
TYPED_TEST(RobotDerivatives, InertiaDerivativesAreTheJetAndFiniteDifferenceDerivatives) {
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

// An inertia matrix that is not positive definite is reported, not inverted.
TYPED_TEST(RobotDerivatives, ForwardDynamicsDerivativesRefuseAnIndefiniteInertia) {
  using M = TypeParam;
  this->for_states([&](const State<M>& s, const ParameterVector<M>&) {
    const ParameterVector<M> phi = -this->physical_phi();  // M(q; -phi) = -M(q; phi) + constant part
    const Eigen::Matrix<double, M::nq, M::nq> A = M::inertia(s.q, phi);
    const double smallest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, M::nq, M::nq>>(A).eigenvalues().minCoeff();
    typename M::template ForwardDynamicsDerivatives<double> d;
    const bool ok = M::forward_dynamics_derivatives(s.q, s.qd, this->random_torque(), phi, d);
    EXPECT_EQ(ok, smallest > 0) << "smallest eigenvalue of M " << smallest << ", smallest pivot " << d.min_pivot;
  });
}

}  // namespace
}  // namespace symoro::test
