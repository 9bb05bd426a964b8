// Constants the runtime's units share, defined once: several units compile as one in a unity
// build (CMAKE_UNITY_BUILD), where a constant of the same name in two of them would collide.
#pragma once

#include <limits>

namespace symoro::detail {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kDeg = kPi / 180.0;  // one degree in radians
inline constexpr double nan = std::numeric_limits<double>::quiet_NaN();

}  // namespace symoro::detail
