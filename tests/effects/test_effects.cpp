// Model-gap effects compiled into a variant (robot.yaml `effects`), on planar2r::effects:
//   coulomb [1] (FS1 un-fixed while "FS*" fixes the rest), offset [1, 2], stribeck joint 2 at
//   0.05 rad/s, viscous_asymmetry [2], position_harmonics joint 1, orders 1 and 2,
//   smooth_coulomb joint 2 at 0.04 rad/s (FS2 stays fixed to 0), tustin_stribeck joint 2 at
//   0.08 rad/s (a row of the effect table that only its law describes).
// Every regressor column is checked against its term written out here, then the functions
// against each other and against the robot's full model, and the Jet derivatives of the new
// terms against finite differences.
#include <symoro/planar2r.hpp>

#include <array>
#include <cmath>
#include <string>

#include <Eigen/Core>
#include <Eigen/LU>
#include <gtest/gtest.h>

#include "jet_support.hpp"
#include "test_support.hpp"

namespace symoro::test {
namespace {

namespace fx = symoro::planar2r::effects;
using Effects = fx::Model;
using Full = symoro::planar2r::Model;
using V2 = Eigen::Vector2d;

constexpr double kStribeckVelocity = 0.05;  // robot.yaml
constexpr double kCoulombVelocity = 0.04;   // robot.yaml, smooth_coulomb
constexpr double kTustinVelocity = 0.08;    // robot.yaml, tustin_stribeck
constexpr double kTight = 1e-13;
constexpr double kRelTol = 1e-9;
constexpr int kStates = 40;

double sgn(double x) { return double((x > 0) - (x < 0)); }

// The hand-written effect torque of joint 1 and joint 2 for phi's effect entries.
V2 effect_torque_by_hand(const V2& q, const V2& qd, const ParameterVector<Effects>& phi) {
  using namespace fx::param;
  const double v = kStribeckVelocity;
  V2 tau;
  tau(0) = phi(OFF1) + phi(HS1_1) * std::sin(q(0)) + phi(HC1_1) * std::cos(q(0)) + phi(HS1_2) * std::sin(2 * q(0)) +
           phi(HC1_2) * std::cos(2 * q(0));
  tau(1) = phi(OFF2) + phi(FST2) * sgn(qd(1)) * std::exp(-std::pow(qd(1) / v, 2)) + phi(FVA2) * std::fabs(qd(1)) +
           phi(FC2) * std::tanh(qd(1) / kCoulombVelocity) +
           phi(FSE2) * sgn(qd(1)) * std::exp(-std::fabs(qd(1)) / kTustinVelocity);
  return tau;
}

class PlanarEffects : public ::testing::Test {
 protected:
  // A state with |qd2| in [0.005, 0.12] every other time, where the Stribeck term is far from 0.
  State<Effects> state(int k) {
    State<Effects> s = random_state<Effects>(rng_);
    if (k % 2 == 0) s.qd(1) = rng_.signed_uniform(0.005, 0.12);
    return s;
  }
  ParameterVector<Effects> phi() { return random_phi<Effects>(rng_); }
  // Physical inertial parameters (M positive definite) and order-1 effect parameters.
  ParameterVector<Effects> physical_phi() {
    return Effects::base_from_standard(random_standard_parameters<Effects>(rng_).s);
  }
  Random rng_{73};
};

TEST_F(PlanarEffects, ParametersAreAppendedInCanonicalOrderWithUnits) {
  static_assert(Effects::np == 20 && Effects::ne == 10 && Effects::ns == Full::ns + 10);
  const std::array<const char*, 20> names = {"ZZR1",  "MXR1",  "MY1",   "ZZ2",   "MX2",  "MY2",  "IA2",
                                             "FV1",   "FV2",   "FS1",   "OFF1",  "OFF2", "FST2", "FVA2",
                                             "HS1_1", "HC1_1", "HS1_2", "HC1_2", "FC2",  "FSE2"};
  const std::array<const char*, 10> units = {"N*m", "N*m", "N*m", "N*m*s/rad", "N*m",
                                             "N*m", "N*m", "N*m", "N*m",       "N*m"};
  const std::array<int, 10> joints = {1, 2, 2, 2, 1, 1, 1, 1, 2, 2};
  for (int i = 0; i < Effects::np; ++i) EXPECT_EQ(std::string(Effects::parameters[i].name), names[i]) << i;
  for (int k = 0; k < 10; ++k) {
    const auto& p = Effects::parameters[10 + k];
    EXPECT_EQ(std::string(p.unit), units[k]) << p.name;
    EXPECT_EQ(p.joint, joints[k]) << p.name;
    EXPECT_EQ(Effects::parent_index[10 + k], -1) << p.name;
  }
  EXPECT_EQ(fx::param::HC1_2, 17);
  EXPECT_EQ(Effects::effect_parameters[2].velocity, kStribeckVelocity);
  EXPECT_EQ(Effects::effect_parameters[6].order, 2);
  EXPECT_EQ(Effects::effect_parameters[8].velocity, kCoulombVelocity);
  EXPECT_EQ(std::string(Effects::effect_parameters[8].family), "FC");
  EXPECT_EQ(Effects::effect_parameters[9].velocity, kTustinVelocity);
  EXPECT_EQ(std::string(Effects::effect_parameters[9].family), "FSE");
  // coulomb [1]: FS1 is identified although "FS*" fixes FS2 (which smooth_coulomb fixes too).
  ASSERT_EQ(Effects::fixed_parameters.size(), 1u);
  EXPECT_EQ(std::string(Effects::fixed_parameters[0].name), "FS2");
  EXPECT_EQ(Effects::fixed_parameters[0].value, 0.0);
}

TEST_F(PlanarEffects, RegressorColumnsAreTheTerms) {
  using namespace fx::param;
  for (int k = 0; k < kStates; ++k) {
    SCOPED_TRACE("state " + std::to_string(k));
    const State<Effects> s = state(k);
    const auto W = Effects::regressor(s.q, s.qd, s.qdd);
    const double q1 = s.q(0), qd1 = s.qd(0), qd2 = s.qd(1);
    const auto expect_column = [&](int column, double row1, double row2) {
      EXPECT_NEAR(W(0, column), row1, kTight) << Effects::parameters[column].name;
      EXPECT_NEAR(W(1, column), row2, kTight) << Effects::parameters[column].name;
    };
    expect_column(FS1, sgn(qd1), 0.0);
    expect_column(OFF1, 1.0, 0.0);
    expect_column(OFF2, 0.0, 1.0);
    expect_column(FST2, 0.0, sgn(qd2) * std::exp(-std::pow(qd2 / kStribeckVelocity, 2)));
    expect_column(FVA2, 0.0, std::fabs(qd2));
    expect_column(HS1_1, std::sin(q1), 0.0);
    expect_column(HC1_1, std::cos(q1), 0.0);
    expect_column(HS1_2, std::sin(2 * q1), 0.0);
    expect_column(HC1_2, std::cos(2 * q1), 0.0);
    expect_column(FC2, 0.0, std::tanh(qd2 / kCoulombVelocity));
    expect_column(FSE2, 0.0, sgn(qd2) * std::exp(-std::fabs(qd2) / kTustinVelocity));
    // The base parameters' columns are the full model's.
    const auto Wf = Full::regressor(s.q, s.qd, s.qdd);
    for (int i = 0; i < Effects::np - Effects::ne; ++i)
      EXPECT_TRUE(close(W.col(i), Wf.col(Effects::parent_index[i]), kTight)) << Effects::parameters[i].name;
  }
}

TEST_F(PlanarEffects, FunctionsAgreeAndAddTheTermsToTheFullModel) {
  for (int k = 0; k < kStates; ++k) {
    SCOPED_TRACE("state " + std::to_string(k));
    const State<Effects> s = state(k);
    const ParameterVector<Effects> phi = this->phi();
    const V2 tau = Effects::inverse_dynamics(s.q, s.qd, s.qdd, phi);
    EXPECT_TRUE(
        close(Effects::regressor(s.q, s.qd, s.qdd) * phi + Effects::fixed_torque(s.q, s.qd, s.qdd), tau, kRelTol));
    EXPECT_TRUE(Effects::fixed_torque(s.q, s.qd, s.qdd).isZero(0.0));
    const V2 by_hand = effect_torque_by_hand(s.q, s.qd, phi);
    const auto full_phi = Effects::to_parent(phi);
    EXPECT_TRUE(close(tau, Full::inverse_dynamics(s.q, s.qd, s.qdd, full_phi) + by_hand, kRelTol));
    EXPECT_TRUE(close(Effects::nonlinear_effects(s.q, s.qd, phi),
                      Full::nonlinear_effects(s.q, s.qd, full_phi) + by_hand, kRelTol));
    EXPECT_TRUE(close(Effects::inertia(s.q, phi), Full::inertia(s.q, full_phi), kRelTol));
    EXPECT_TRUE(close(Effects::inertia(s.q, phi) * s.qdd + Effects::nonlinear_effects(s.q, s.qd, phi), tau, kRelTol));
  }
}

TEST_F(PlanarEffects, ForwardDynamicsInvertsInverseDynamics) {
  for (int k = 0; k < kStates; ++k) {
    SCOPED_TRACE("state " + std::to_string(k));
    const State<Effects> s = state(k);
    const ParameterVector<Effects> phi = physical_phi();
    const V2 tau = Effects::inverse_dynamics(s.q, s.qd, s.qdd, phi);
    EXPECT_TRUE(close(Effects::forward_dynamics(s.q, s.qd, tau, phi), s.qdd, kRelTol));
    // and the full model sees the torque less the effects'.
    const V2 net = tau - effect_torque_by_hand(s.q, s.qd, phi);
    EXPECT_TRUE(close(Full::forward_dynamics(s.q, s.qd, net, Effects::to_parent(phi)), s.qdd, kRelTol));
  }
}

TEST_F(PlanarEffects, BaseFromStandardMapsEffectParametersIdentically) {
  const auto standard = standard_parameters_of_variant<Effects>(rng_);  // FS2 = 0, as fixed
  const ParameterVector<Effects> phi = Effects::base_from_standard(standard.s);
  EXPECT_TRUE((phi.tail<10>().array() == standard.s.tail<10>().array()).all());
  EXPECT_TRUE(close(Effects::to_parent(phi), Full::base_from_standard(standard.s.head<Full::ns>()), kTight));
  for (int k = 0; k < 10; ++k)
    EXPECT_EQ(std::string(Effects::standard_parameters[Full::ns + k].name), Effects::effect_parameters[k].name);
  EXPECT_TRUE(Effects::from_parent(Effects::to_parent(phi)).tail<10>().isZero(0.0));
}

// Derivatives in q and qd (Jets seeded on both) of every regressor column and of the torque,
// against central differences; |qd2| stays far above the step, away from sign's jump.
TEST_F(PlanarEffects, JetDerivativesOfTheTermsMatchFiniteDifferences) {
  using Jet = ceres::Jet<double, 4>;
  using J2 = Eigen::Matrix<Jet, 2, 1>;
  for (int k = 0; k < kStates; ++k) {
    SCOPED_TRACE("state " + std::to_string(k));
    const State<Effects> s = state(k);
    const ParameterVector<Effects> phi = this->phi();
    const Eigen::Vector4d x(s.q(0), s.q(1), s.qd(0), s.qd(1));
    J2 q, qd;
    for (int i = 0; i < 2; ++i) {
      q(i) = Jet(s.q(i), i);
      qd(i) = Jet(s.qd(i), 2 + i);
    }
    const auto regressor_at = [&](const Eigen::Vector4d& y) {
      return Effects::regressor(V2(y.head<2>()), V2(y.tail<2>()), s.qdd);
    };
    const auto tau_at = [&](const Eigen::Vector4d& y) {
      return Effects::inverse_dynamics(V2(y.head<2>()), V2(y.tail<2>()), s.qdd, phi);
    };
    const Eigen::MatrixXd W_jet = jet_jacobian(Effects::regressor(q, qd, s.qdd));
    const Eigen::MatrixXd W_fd = finite_difference_jacobian(regressor_at, x, 1e-7);
    // Rows of d vec(W) / dx for the 10 effect columns (column-major: entry (r, c) is row 2c + r):
    // relative 1e-6, or 1e-8 absolute where the derivative is below the central difference's
    // round-off (eps |W| / h ~ 1e-9: saturated tanh and Stribeck terms).
    for (int c = Effects::np - Effects::ne; c < Effects::np; ++c) {
      const Eigen::MatrixXd a = W_jet.middleRows(2 * c, 2), b = W_fd.middleRows(2 * c, 2);
      EXPECT_TRUE(close(a, b, 1e-6) || (a - b).cwiseAbs().maxCoeff() < 1e-8) << Effects::parameters[c].name;
    }
    // Against the hand-written derivative of the Stribeck term as well.
    const double qd2 = s.qd(1), v = kStribeckVelocity;
    const double dfst = -2.0 * qd2 / (v * v) * sgn(qd2) * std::exp(-std::pow(qd2 / v, 2));
    EXPECT_NEAR(W_jet(2 * fx::param::FST2 + 1, 3), dfst, 1e-12 * (1 + std::fabs(dfst)));
    EXPECT_NEAR(W_jet(2 * fx::param::HS1_2, 0), 2 * std::cos(2 * s.q(0)), 1e-13);
    EXPECT_NEAR(W_jet(2 * fx::param::FVA2 + 1, 3), sgn(qd2), 1e-15);
    const double th = std::tanh(qd2 / kCoulombVelocity), dfc = (1 - th * th) / kCoulombVelocity;
    EXPECT_NEAR(W_jet(2 * fx::param::FC2 + 1, 3), dfc, 1e-12 * (1 + std::fabs(dfc)));
    const double dfse = -std::exp(-std::fabs(qd2) / kTustinVelocity) / kTustinVelocity;
    EXPECT_NEAR(W_jet(2 * fx::param::FSE2 + 1, 3), dfse, 1e-12 * (1 + std::fabs(dfse)));
    EXPECT_TRUE(close(jet_jacobian(Effects::inverse_dynamics(q, qd, s.qdd, phi)),
                      finite_difference_jacobian(tau_at, x, 1e-7), 1e-6));
  }
}

}  // namespace
}  // namespace symoro::test
