// DYNAMIXEL Protocol 2.0 packets and their encoding (source: the ROBOTIS e-manual,
// https://emanual.robotis.com/docs/en/dxl/protocol2/).
//
//   FF FF FD 00 | ID | LEN_L LEN_H | INST | [ERR] PARAM... | CRC_L CRC_H
//
// Length counts the bytes after it: instruction, (status error), parameters and the CRC, after
// byte stuffing. Byte stuffing: in the instruction-to-parameters region every "FF FF FD" is sent
// as "FF FF FD FD", so that a header never appears inside a packet; the CRC is computed over the
// stuffed bytes. Status packets (instruction 0x55) carry an error byte before the parameters.
// Decoding a byte stream is decoder.hpp's job.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "symoro/dynamixel/span.hpp"

namespace symoro::dynamixel {

inline constexpr std::uint8_t kHeader[4] = {0xFF, 0xFF, 0xFD, 0x00};
inline constexpr std::uint8_t kBroadcastId = 0xFE;
inline constexpr std::uint8_t kMaxId = 0xFC;   // 0..252; 253 and 255 would look like a header
inline constexpr std::size_t kHeaderSize = 7;  // header, ID and Length
inline constexpr std::size_t kCrcSize = 2;

// Valid packet IDs: 0..252 and the broadcast ID 254.
constexpr bool is_valid_id(std::uint8_t id) { return id <= kMaxId || id == kBroadcastId; }

enum class Instruction : std::uint8_t {
  ping = 0x01,
  read = 0x02,
  write = 0x03,
  reg_write = 0x04,
  action = 0x05,
  factory_reset = 0x06,
  reboot = 0x08,
  clear = 0x10,
  status = 0x55,
  sync_read = 0x82,
  sync_write = 0x83,
  bulk_read = 0x92,
  bulk_write = 0x93,
};

// The instructions the e-manual's Protocol 2.0 page defines (the decoder rejects the others).
bool is_known_instruction(std::uint8_t value);
const char* to_string(Instruction instruction);

// The status packet's error byte: bit 7 is the hardware alert (details in the control table's
// Hardware Error Status), bits 0..6 hold one error number (not a bit set, unlike Protocol 1.0).
enum class ErrorNumber : std::uint8_t {
  none = 0x00,
  result_fail = 0x01,        // failed to process the instruction packet
  instruction_error = 0x02,  // undefined instruction, or Action without Reg Write
  crc_error = 0x03,          // the instruction packet's CRC did not match
  data_range_error = 0x04,   // value outside the item's minimum/maximum
  data_length_error = 0x05,  // fewer bytes written than the item's size
  data_limit_error = 0x06,   // value outside the item's limit
  access_error = 0x07,       // read-only/undefined address, or EEPROM write with torque on
};
const char* to_string(ErrorNumber number);

struct StatusError {
  std::uint8_t raw = 0;
  constexpr bool alert() const { return (raw & 0x80) != 0; }
  constexpr ErrorNumber number() const { return static_cast<ErrorNumber>(raw & 0x7F); }
  // The instruction was processed (the alert bit may still be set).
  constexpr bool ok() const { return (raw & 0x7F) == 0; }
};

// A decoded or to-be-encoded packet. `params` are the unstuffed parameters (for a status packet,
// the bytes after the error byte); the view does not own them.
struct Packet {
  std::uint8_t id = 0;
  Instruction instruction = Instruction::ping;
  std::uint8_t error = 0;  // status packets only
  ByteView params;

  bool is_status() const { return instruction == Instruction::status; }
  StatusError status_error() const { return StatusError{error}; }
};

// Writes one packet into a caller's vector, stuffing bytes as they are appended, so that building
// a packet allocates nothing once the vector's capacity suffices (reuse it in a control loop).
//   PacketWriter w(out, id, Instruction::write);  w.u16(address).bytes(data);  w.finish();
// Throws std::invalid_argument for an invalid ID and std::length_error when the stuffed packet
// does not fit the 16-bit Length field.
class PacketWriter {
 public:
  PacketWriter(std::vector<std::uint8_t>& out, std::uint8_t id, Instruction instruction);

  PacketWriter& u8(std::uint8_t value);
  PacketWriter& u16(std::uint16_t value);
  PacketWriter& u32(std::uint32_t value);
  PacketWriter& bytes(ByteView values);
  // Patches Length and appends the CRC; returns the whole packet (a view of `out`).
  ByteView finish();

 private:
  std::vector<std::uint8_t>& out_;
  int ff_run_ = 0;  // trailing 0xFF bytes written in the stuffed region (saturates at 2)
};

// The packet's wire bytes into `out` (cleared first). Status packets include the error byte.
ByteView encode(const Packet& packet, std::vector<std::uint8_t>& out);

// Upper bound on the wire size of a packet whose region (instruction, error, parameters) has
// `region_size` bytes: stuffing adds at most one byte per three.
constexpr std::size_t max_encoded_size(std::size_t region_size) {
  return kHeaderSize + region_size + region_size / 3 + kCrcSize;
}

}  // namespace symoro::dynamixel
