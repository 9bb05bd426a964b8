// The robot's models (its full model and every variant) as GoogleTest types, named "full" or by
// the variant: what test_robot.cpp and the derivative units (derivatives_support.hpp) type their
// suites over. Needs SYMORO_ROBOT_HEADER and SYMORO_ROBOT_NS (tests/CMakeLists.txt).
#pragma once

#include SYMORO_ROBOT_HEADER

#include <string>
#include <tuple>

#include <gtest/gtest.h>

namespace symoro::test {
namespace {

template <class Tuple>
struct AsTypes;
template <class... Model>
struct AsTypes<std::tuple<Model...>> {
  using type = ::testing::Types<Model...>;
};
using Models = AsTypes<SYMORO_ROBOT_NS::Models>::type;

// Test names: "full" for the robot's full model, else the variant's name.
struct ModelName {
  template <class Model>
  static std::string GetName(int) {
    const std::string variant = Model::variant_name;
    return variant.empty() ? "full" : variant;
  }
};

}  // namespace
}  // namespace symoro::test
