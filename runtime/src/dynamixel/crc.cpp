#include "symoro/dynamixel/crc.hpp"

#include <array>

namespace symoro::dynamixel {
namespace {

// table[i] is the CRC register after shifting byte i through a zero register: one lookup then
// replaces eight shift-and-XOR steps.
constexpr std::array<std::uint16_t, 256> make_table() {
  std::array<std::uint16_t, 256> table{};
  for (unsigned i = 0; i < 256; ++i) {
    std::uint16_t r = static_cast<std::uint16_t>(i << 8);
    for (int bit = 0; bit < 8; ++bit) r = static_cast<std::uint16_t>((r & 0x8000) ? (r << 1) ^ 0x8005 : (r << 1));
    table[i] = r;
  }
  return table;
}

constexpr std::array<std::uint16_t, 256> kTable = make_table();
static_assert(kTable[1] == 0x8005 && kTable[255] == 0x0202);

}  // namespace

std::uint16_t crc16(const std::uint8_t* data, std::size_t size, std::uint16_t crc) {
  for (std::size_t i = 0; i < size; ++i)
    crc = static_cast<std::uint16_t>((crc << 8) ^ kTable[((crc >> 8) ^ data[i]) & 0xFF]);
  return crc;
}

}  // namespace symoro::dynamixel
