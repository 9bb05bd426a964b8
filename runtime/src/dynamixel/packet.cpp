#include "symoro/dynamixel/packet.hpp"

#include <stdexcept>
#include <string>

#include "symoro/dynamixel/crc.hpp"

namespace symoro::dynamixel {

bool is_known_instruction(std::uint8_t value) {
  switch (static_cast<Instruction>(value)) {
    case Instruction::ping:
    case Instruction::read:
    case Instruction::write:
    case Instruction::reg_write:
    case Instruction::action:
    case Instruction::factory_reset:
    case Instruction::reboot:
    case Instruction::clear:
    case Instruction::status:
    case Instruction::sync_read:
    case Instruction::sync_write:
    case Instruction::bulk_read:
    case Instruction::bulk_write:
      return true;
  }
  return false;
}

const char* to_string(Instruction instruction) {
  switch (instruction) {
    case Instruction::ping:
      return "ping";
    case Instruction::read:
      return "read";
    case Instruction::write:
      return "write";
    case Instruction::reg_write:
      return "reg write";
    case Instruction::action:
      return "action";
    case Instruction::factory_reset:
      return "factory reset";
    case Instruction::reboot:
      return "reboot";
    case Instruction::clear:
      return "clear";
    case Instruction::status:
      return "status";
    case Instruction::sync_read:
      return "sync read";
    case Instruction::sync_write:
      return "sync write";
    case Instruction::bulk_read:
      return "bulk read";
    case Instruction::bulk_write:
      return "bulk write";
  }
  return "unknown instruction";
}

const char* to_string(ErrorNumber number) {
  switch (number) {
    case ErrorNumber::none:
      return "no error";
    case ErrorNumber::result_fail:
      return "result fail";
    case ErrorNumber::instruction_error:
      return "instruction error";
    case ErrorNumber::crc_error:
      return "CRC error";
    case ErrorNumber::data_range_error:
      return "data range error";
    case ErrorNumber::data_length_error:
      return "data length error";
    case ErrorNumber::data_limit_error:
      return "data limit error";
    case ErrorNumber::access_error:
      return "access error";
  }
  return "unknown error number";
}

PacketWriter::PacketWriter(std::vector<std::uint8_t>& out, std::uint8_t id, Instruction instruction) : out_(out) {
  if (!is_valid_id(id))
    throw std::invalid_argument("DYNAMIXEL packet: ID " + std::to_string(id) +
                                " is not 0..252 or the broadcast ID 254");
  out_.clear();
  for (std::uint8_t b : kHeader) out_.push_back(b);
  out_.push_back(id);
  out_.push_back(0);  // Length, patched by finish()
  out_.push_back(0);
  u8(static_cast<std::uint8_t>(instruction));  // the stuffed region starts at the instruction
}

PacketWriter& PacketWriter::u8(std::uint8_t value) {
  out_.push_back(value);
  if (value == 0xFD && ff_run_ == 2) {
    out_.push_back(0xFD);  // FF FF FD -> FF FF FD FD
    ff_run_ = 0;
  } else {
    ff_run_ = value == 0xFF ? (ff_run_ < 2 ? ff_run_ + 1 : 2) : 0;
  }
  return *this;
}

PacketWriter& PacketWriter::u16(std::uint16_t value) {
  return u8(static_cast<std::uint8_t>(value)).u8(static_cast<std::uint8_t>(value >> 8));
}

PacketWriter& PacketWriter::u32(std::uint32_t value) {
  return u16(static_cast<std::uint16_t>(value)).u16(static_cast<std::uint16_t>(value >> 16));
}

PacketWriter& PacketWriter::bytes(ByteView values) {
  for (std::uint8_t v : values) u8(v);
  return *this;
}

ByteView PacketWriter::finish() {
  const std::size_t length = out_.size() - kHeaderSize + kCrcSize;
  if (length > 0xFFFF)
    throw std::length_error("DYNAMIXEL packet: Length " + std::to_string(length) + " does not fit 16 bits");
  out_[5] = static_cast<std::uint8_t>(length);
  out_[6] = static_cast<std::uint8_t>(length >> 8);
  const std::uint16_t crc = crc16(out_.data(), out_.size());
  out_.push_back(static_cast<std::uint8_t>(crc));
  out_.push_back(static_cast<std::uint8_t>(crc >> 8));
  return ByteView(out_.data(), out_.size());
}

ByteView encode(const Packet& packet, std::vector<std::uint8_t>& out) {
  PacketWriter w(out, packet.id, packet.instruction);
  if (packet.is_status()) w.u8(packet.error);
  w.bytes(packet.params);
  return w.finish();
}

}  // namespace symoro::dynamixel
