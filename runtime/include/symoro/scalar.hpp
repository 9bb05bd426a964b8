// Scalar helpers used by generated code. They work for double and for any type that behaves
// like a number with comparison on its value, such as ceres::Jet, without including Ceres.
#pragma once

#include <type_traits>

namespace symoro {

// sign(x): -1, 0 or +1 as a constant of the scalar type. For a Jet the derivative is zero,
// which is the derivative of sign everywhere but at 0.
template <class Scalar>
inline Scalar sign(const Scalar& x) {
  if (x > Scalar(0)) return Scalar(1.0);
  if (x < Scalar(0)) return Scalar(-1.0);
  return Scalar(0.0);
}

// promote_t<A, B, ...>: the scalar a computation on mixed inputs produces. Plain floating point
// types give way to any other scalar (a Jet); among floating point types the widest wins.
template <class... T>
struct promote;
template <class T>
struct promote<T> {
  using type = T;
};
template <class A, class B, class... Rest>
struct promote<A, B, Rest...> {
  using AB = std::conditional_t<std::is_floating_point_v<A>,
                                std::conditional_t<std::is_floating_point_v<B>, std::common_type_t<A, B>, B>, A>;
  using type = typename promote<AB, Rest...>::type;
};
template <class... T>
using promote_t = typename promote<T...>::type;

}  // namespace symoro
