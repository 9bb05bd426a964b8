// What the derivative test units of one robot share (test_robot_derivatives_*.cpp, one unit per
// generated function so that no unit instantiates every Jet at once: the crane_x7 unit took 14 min
// and 4.8 GB as one): its models as gtest types, the tolerances and random states. Built into
// test_robot_<robot> with test_robot.cpp.
#pragma once

#include SYMORO_ROBOT_HEADER

#include <string>
#include <tuple>

#include <gtest/gtest.h>

#include "jet_support.hpp"
#include "robot_models.hpp"
#include "test_support.hpp"

namespace symoro::test {
namespace {

// Generated derivative vs Jet derivative of the generated value: the same exact derivative in a
// different order of operations; 1e-10 of the object's magnitude (round-off, times the
// conditioning of M for the forward dynamics). The Jets are Duals along a random direction v
// (jet_support.hpp), compared with the generated derivative times v.
constexpr double kJetTol = 1e-10;
// Central differences: kFdStep, kFdTol and kStates (test_support.hpp).

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
  // A random direction for the Jet references (jet_support.hpp), entries in [-1, 1], from a
  // generator of its own: the states and parameters stay those drawn from rng_.
  template <class Vector>
  Vector random_direction() {
    return direction_rng_.vector<Vector>(Vector::RowsAtCompileTime, -1, 1);
  }

  Random rng_{20261124};
  Random direction_rng_{20261125};
};
}  // namespace
}  // namespace symoro::test
