// The robot's models (its full model and every variant) as GoogleTest types, named "full" or by
// the variant: what test_robot.cpp and the derivative units (derivatives_support.hpp) type their
// suites over. Needs SYMORO_ROBOT_HEADER and SYMORO_ROBOT_NS (tests/CMakeLists.txt).
//
// tests/CMakeLists.txt may compile a test unit in parts by model (issue 27: a crane_x7 unit
// instantiating its three models took minutes at -j2): SYMORO_TEST_MODEL=i keeps model i of the
// robot's Models only, and with SYMORO_TEST_MODEL_TAIL=1 every later one too (the last part, so
// that a model count that is too low still tests every model). Without SYMORO_TEST_MODEL, all.
#pragma once

#include SYMORO_ROBOT_HEADER

#include <cstddef>
#include <string>
#include <tuple>
#include <utility>

#include <gtest/gtest.h>

namespace symoro::test {
namespace {

template <class Tuple>
struct AsTypes;
template <class... Model>
struct AsTypes<std::tuple<Model...>> {
  using type = ::testing::Types<Model...>;
};

#ifdef SYMORO_TEST_MODEL
// Models first, first + 1, ..., first + count - 1 of Tuple.
template <class Tuple, std::size_t first, std::size_t... i>
std::tuple<std::tuple_element_t<first + i, Tuple>...> models_from(std::index_sequence<i...>);

#ifndef SYMORO_TEST_MODEL_TAIL
#define SYMORO_TEST_MODEL_TAIL 0
#endif
constexpr std::size_t kAllModels = std::tuple_size_v<SYMORO_ROBOT_NS::Models>;
static_assert(SYMORO_TEST_MODEL < kAllModels,
              "tests/CMakeLists.txt counts more models than the robot's Models (robot.yaml's variants)");
constexpr std::size_t kUnitModels = SYMORO_TEST_MODEL_TAIL ? kAllModels - SYMORO_TEST_MODEL : 1;
using Models = AsTypes<decltype(models_from<SYMORO_ROBOT_NS::Models, SYMORO_TEST_MODEL>(
    std::make_index_sequence<kUnitModels>{}))>::type;
#else
using Models = AsTypes<SYMORO_ROBOT_NS::Models>::type;
#endif

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
