// Little-endian load and store of 1, 2 and 4-byte control-table values and protocol fields.
// Protocol 2.0 sends every multi-byte field low byte first (e-manual, Protocol 2.0: "Len_L,
// Len_H", "Low-order byte from the starting address"). Signed items (Goal Current, Present
// Velocity, ...) are two's complement of their own width, so load_le<std::int16_t> gives the
// signed value of a 2-byte item.
#pragma once

#include <cstdint>
#include <type_traits>

namespace symoro::dynamixel {

template <class T>
constexpr T load_le(const std::uint8_t* p) {
  static_assert(std::is_integral_v<T> && (sizeof(T) == 1 || sizeof(T) == 2 || sizeof(T) == 4));
  using U = std::make_unsigned_t<T>;
  std::uint32_t v = 0;
  for (unsigned i = 0; i < sizeof(T); ++i) v |= std::uint32_t{p[i]} << (8 * i);
  return static_cast<T>(static_cast<U>(v));  // two's complement reinterpretation for signed T
}

template <class T>
constexpr void store_le(std::uint8_t* p, T value) {
  static_assert(std::is_integral_v<T> && (sizeof(T) == 1 || sizeof(T) == 2 || sizeof(T) == 4));
  const auto v = static_cast<std::uint32_t>(static_cast<std::make_unsigned_t<T>>(value));
  for (unsigned i = 0; i < sizeof(T); ++i) p[i] = static_cast<std::uint8_t>(v >> (8 * i));
}

// A value of `size` (1, 2 or 4) bytes, zero- or sign-extended to 32 bits; other sizes give 0.
constexpr std::uint32_t load_le_unsigned(const std::uint8_t* p, unsigned size) {
  switch (size) {
    case 1:
      return load_le<std::uint8_t>(p);
    case 2:
      return load_le<std::uint16_t>(p);
    case 4:
      return load_le<std::uint32_t>(p);
    default:
      return 0;
  }
}
constexpr std::int32_t load_le_signed(const std::uint8_t* p, unsigned size) {
  switch (size) {
    case 1:
      return load_le<std::int8_t>(p);
    case 2:
      return load_le<std::int16_t>(p);
    case 4:
      return load_le<std::int32_t>(p);
    default:
      return 0;
  }
}

}  // namespace symoro::dynamixel
