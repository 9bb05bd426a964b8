// The CRC of DYNAMIXEL Protocol 2.0: CRC-16 with polynomial 0x8005 (x^16 + x^15 + x^2 + 1),
// initial value 0, bits processed most significant first, no final XOR (the "CRC-16-IBM" of the
// e-manual; the catalogue name is CRC-16/BUYPASS, check value 0xFEE8 for "123456789"). A packet's
// CRC covers every byte from Header 1 to the last parameter, after byte stuffing, and is sent low
// byte first. Source: https://emanual.robotis.com/docs/en/dxl/protocol2/ (CRC; the packet
// examples there are the test vectors) and https://emanual.robotis.com/docs/en/dxl/crc/.
#pragma once

#include <cstddef>
#include <cstdint>

#include "symoro/dynamixel/span.hpp"

namespace symoro::dynamixel {

// Continues `crc` over `size` bytes (pass the previous result to checksum a message in pieces).
std::uint16_t crc16(const std::uint8_t* data, std::size_t size, std::uint16_t crc = 0);
inline std::uint16_t crc16(ByteView bytes, std::uint16_t crc = 0) { return crc16(bytes.data(), bytes.size(), crc); }

}  // namespace symoro::dynamixel
