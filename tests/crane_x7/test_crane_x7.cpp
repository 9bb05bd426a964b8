// CRANE-X7 specifics: the 65- and 39-parameter models, the paper's parameter list, and the
// reduced variant of the full robot (symoro::crane_x7::reduced) against OpenSYMORO's own
// 39-parameter files (robots/crane_x7_reduced) and against the model generated from them
// (symoro::crane_x7_reduced). See ../shared/crane_x7/FACTS.md.
#include <symoro/crane_x7.hpp>
#include <symoro/crane_x7_reduced.hpp>

#include <string>
#include <vector>

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "reference.hpp"
#include "test_support.hpp"

namespace symoro::test {
namespace {

using Reduced = symoro::crane_x7::reduced::Model;      // variant of the full robot
using ReducedFiles = symoro::crane_x7_reduced::Model;  // generated from OpenSYMORO's reduced files

// Same tolerance and reasoning as tests/robot: different evaluation orders of the same model.
constexpr double kRelTol = 1e-9;
constexpr int kStates = 20;

const Reference& reduced_files() { return reference(SYMORO_ROBOTS_DIR "/crane_x7_reduced"); }

template <class Model>
int index_of(const std::string& name) {
  for (int k = 0; k < Model::np; ++k)
    if (name == Model::parameters[k].name) return k;
  throw std::runtime_error(name + " is not a parameter of " + Model::robot_name);
}

// phi of one model laid out for another by parameter name.
template <class To, class From>
ParameterVector<To> by_name(const ParameterVector<From>& phi) {
  ParameterVector<To> out;
  for (int i = 0; i < To::np; ++i) out(i) = phi(index_of<From>(To::parameters[i].name));
  return out;
}

template <class Model>
ParameterValues values_by_name(const ParameterVector<Model>& phi) {
  ParameterValues v;
  for (int i = 0; i < Model::np; ++i) v[Model::parameters[i].name] = phi(i);
  return v;
}

class CraneX7 : public ::testing::Test {
 protected:
  // Calls check(state, phi) at kStates random states, phi from physical standard parameters so
  // that M is positive definite (the forward dynamics inverts it).
  template <class Check>
  void for_states(const Check& check) {
    for (int k = 0; k < kStates; ++k) {
      SCOPED_TRACE("random state " + std::to_string(k));
      const State<Reduced> s = random_state<Reduced>(rng_);
      check(s, Reduced::base_from_standard(random_standard_parameters<Reduced>(rng_).s));
    }
  }
  JointVector<Reduced> random_torque() { return rng_.vector<JointVector<Reduced>>(Reduced::nq, -3, 3); }

  Random rng_{7};
};

TEST_F(CraneX7, ParameterCounts) {
  EXPECT_EQ(symoro::crane_x7::np, 65);
  EXPECT_EQ(symoro::crane_x7::reduced::np, 39);
  EXPECT_EQ(symoro::crane_x7::nq, 8);
  EXPECT_EQ(symoro::crane_x7_reduced::np, 39);
}

TEST_F(CraneX7, ReducedParametersAreThePapersInOrder) {
  const std::vector<std::string> paper = {
      "ZZR1", "XXR2", "ZZR2", "MX2",  "MYR2", "XXR3", "ZZR3", "MX3",  "MYR3", "XXR4", "ZZR4", "MX4", "MYR4",
      "XXR5", "ZZR5", "MX5",  "MYR5", "XXR6", "ZZR6", "MX6",  "MYR6", "XXR7", "ZZ7",  "MX7",  "MY7", "IA3",
      "IA4",  "IA5",  "IA6",  "IA7",  "IA8",  "FV1",  "FV2",  "FV3",  "FV4",  "FV5",  "FV6",  "FV7", "FV8"};
  EXPECT_EQ(parameter_names<Reduced>(), paper);
  EXPECT_EQ(parameter_names<ReducedFiles>(), paper);
}

// The variant's specialized regressor is OpenSYMORO's 39-column dim.txt, column by column.
TEST_F(CraneX7, ReducedRegressorIsOpenSymorosReducedDim) {
  const auto names = parameter_names<Reduced>();
  for_states([&](const State<Reduced>& s, const auto&) {
    EXPECT_TRUE(close(symoro::crane_x7::reduced::regressor(s.q, s.qd, s.qdd),
                      reduced_files().regressor(s.q, s.qd, s.qdd, names), kRelTol, names));
  });
}

TEST_F(CraneX7, ReducedDynamicsAreOpenSymorosReducedModels) {
  for_states([&](const State<Reduced>& s, const ParameterVector<Reduced>& phi) {
    const ParameterValues values = values_by_name<Reduced>(phi);
    const JointVector<Reduced> tau = random_torque();
    EXPECT_TRUE(close(Reduced::inverse_dynamics(s.q, s.qd, s.qdd, phi),
                      reduced_files().inverse_dynamics(s.q, s.qd, s.qdd, values), kRelTol))
        << "idm.txt";
    EXPECT_TRUE(close(Reduced::inertia(s.q, phi), reduced_files().inertia(s.q, values), kRelTol)) << "inm.txt";
    EXPECT_TRUE(close(Reduced::nonlinear_effects(s.q, s.qd, phi), reduced_files().nonlinear_effects(s.q, s.qd, values),
                      kRelTol))
        << "ccg.txt";
    EXPECT_TRUE(close(Reduced::forward_dynamics(s.q, s.qd, tau, phi),
                      reduced_files().forward_dynamics(s.q, s.qd, tau, values), kRelTol))
        << "ddm.txt";
  });
}

// Specializing the full model (variant) and generating from the reduced files give one model.
TEST_F(CraneX7, ReducedVariantEqualsTheModelOfTheReducedFiles) {
  const auto names = parameter_names<Reduced>();
  for_states([&](const State<Reduced>& s, const ParameterVector<Reduced>& phi) {
    const ParameterVector<ReducedFiles> other = by_name<ReducedFiles, Reduced>(phi);
    const JointVector<Reduced> tau = random_torque();
    // The files' columns in the variant's order.
    const Eigen::Matrix<double, ReducedFiles::nq, ReducedFiles::np> W = ReducedFiles::regressor(s.q, s.qd, s.qdd);
    Eigen::Matrix<double, Reduced::nq, Reduced::np> W_by_name;
    for (int i = 0; i < Reduced::np; ++i) W_by_name.col(i) = W.col(index_of<ReducedFiles>(names[i]));
    EXPECT_TRUE(close(Reduced::regressor(s.q, s.qd, s.qdd), W_by_name, kRelTol, names));
    EXPECT_TRUE(close(Reduced::inverse_dynamics(s.q, s.qd, s.qdd, phi),
                      ReducedFiles::inverse_dynamics(s.q, s.qd, s.qdd, other), kRelTol));
    EXPECT_TRUE(close(Reduced::inertia(s.q, phi), ReducedFiles::inertia(s.q, other), kRelTol));
    EXPECT_TRUE(
        close(Reduced::nonlinear_effects(s.q, s.qd, phi), ReducedFiles::nonlinear_effects(s.q, s.qd, other), kRelTol));
    EXPECT_TRUE(close(Reduced::forward_dynamics(s.q, s.qd, tau, phi),
                      ReducedFiles::forward_dynamics(s.q, s.qd, tau, other), kRelTol));
    EXPECT_TRUE(close(Reduced::forward_kinematics(s.q), ReducedFiles::forward_kinematics(s.q), kRelTol));
    EXPECT_TRUE(close(Reduced::jacobian(s.q), ReducedFiles::jacobian(s.q), kRelTol));
  });
}

// The reduced variant is the full model with the products of inertia and Coulomb friction at 0.
TEST_F(CraneX7, ReducedIsTheFullModelWithoutProductsAndCoulombFriction) {
  using Full = symoro::crane_x7::Model;
  ASSERT_EQ(Reduced::fixed_parameters.size(), 26u);
  for (const auto& f : Reduced::fixed_parameters) {
    const std::string name = f.name;
    EXPECT_EQ(f.value, 0.0) << name;
    EXPECT_TRUE(name.rfind("XY", 0) == 0 || name.rfind("XZ", 0) == 0 || name.rfind("YZ", 0) == 0 ||
                name.rfind("FS", 0) == 0)
        << name;
  }
  for_states([&](const State<Reduced>& s, const ParameterVector<Reduced>& phi) {
    const Eigen::Matrix<double, Full::np, 1> full = Reduced::to_parent(phi);
    EXPECT_TRUE(close(Reduced::inverse_dynamics(s.q, s.qd, s.qdd, phi), Full::inverse_dynamics(s.q, s.qd, s.qdd, full),
                      kRelTol));
  });
}

}  // namespace
}  // namespace symoro::test
