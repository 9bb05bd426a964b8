#include "symoro/dynamixel/instructions.hpp"

#include <stdexcept>
#include <string>

namespace symoro::dynamixel {

ByteView encode_ping(std::uint8_t id, Buffer& out) { return PacketWriter(out, id, Instruction::ping).finish(); }

ByteView encode_read(std::uint8_t id, std::uint16_t address, std::uint16_t length, Buffer& out) {
  return PacketWriter(out, id, Instruction::read).u16(address).u16(length).finish();
}

ByteView encode_write(std::uint8_t id, std::uint16_t address, ByteView data, Buffer& out) {
  return PacketWriter(out, id, Instruction::write).u16(address).bytes(data).finish();
}

ByteView encode_sync_read(std::uint16_t address, std::uint16_t length, ByteView ids, Buffer& out) {
  PacketWriter w(out, kBroadcastId, Instruction::sync_read);
  w.u16(address).u16(length);
  for (std::uint8_t id : ids) {
    if (id > kMaxId) throw std::invalid_argument("DYNAMIXEL sync read: ID " + std::to_string(id) + " is not 0..252");
    w.u8(id);
  }
  return w.finish();
}

ByteView encode_sync_write(std::uint16_t address, std::uint16_t length, ByteView ids, ByteView data, Buffer& out) {
  if (data.size() != ids.size() * length)
    throw std::invalid_argument("DYNAMIXEL sync write: " + std::to_string(data.size()) + " data bytes for " +
                                std::to_string(ids.size()) + " IDs of " + std::to_string(length) + " bytes each");
  PacketWriter w(out, kBroadcastId, Instruction::sync_write);
  w.u16(address).u16(length);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] > kMaxId)
      throw std::invalid_argument("DYNAMIXEL sync write: ID " + std::to_string(ids[i]) + " is not 0..252");
    w.u8(ids[i]).bytes(data.subspan(i * length, length));
  }
  return w.finish();
}

ByteView encode_bulk_read(Span<const BulkReadItem> items, Buffer& out) {
  PacketWriter w(out, kBroadcastId, Instruction::bulk_read);
  for (const BulkReadItem& item : items) {
    if (item.id > kMaxId)
      throw std::invalid_argument("DYNAMIXEL bulk read: ID " + std::to_string(item.id) + " is not 0..252");
    w.u8(item.id).u16(item.address).u16(item.length);
  }
  return w.finish();
}

ByteView encode_status(std::uint8_t id, std::uint8_t error, ByteView params, Buffer& out) {
  return PacketWriter(out, id, Instruction::status).u8(error).bytes(params).finish();
}

ByteView encode_ping_reply(std::uint8_t id, std::uint16_t model_number, std::uint8_t firmware, Buffer& out,
                           std::uint8_t error) {
  return PacketWriter(out, id, Instruction::status).u8(error).u16(model_number).u8(firmware).finish();
}

std::optional<ReadRequest> parse_read(const Packet& packet) {
  if (packet.instruction != Instruction::read || packet.params.size() != 4) return std::nullopt;
  const std::uint8_t* p = packet.params.data();
  return ReadRequest{load_le<std::uint16_t>(p), load_le<std::uint16_t>(p + 2)};
}

std::optional<WriteRequest> parse_write(const Packet& packet) {
  if (packet.instruction != Instruction::write || packet.params.size() < 2) return std::nullopt;
  return WriteRequest{load_le<std::uint16_t>(packet.params.data()), packet.params.subspan(2)};
}

std::optional<SyncReadRequest> parse_sync_read(const Packet& packet) {
  if (packet.instruction != Instruction::sync_read || packet.params.size() < 4) return std::nullopt;
  const std::uint8_t* p = packet.params.data();
  return SyncReadRequest{load_le<std::uint16_t>(p), load_le<std::uint16_t>(p + 2), packet.params.subspan(4)};
}

std::optional<SyncWriteRequest> parse_sync_write(const Packet& packet) {
  if (packet.instruction != Instruction::sync_write || packet.params.size() < 4) return std::nullopt;
  const std::uint8_t* p = packet.params.data();
  SyncWriteRequest r{load_le<std::uint16_t>(p), load_le<std::uint16_t>(p + 2), packet.params.subspan(4)};
  const std::size_t record = std::size_t{r.length} + 1;
  if (r.records.empty() || r.records.size() % record != 0) return std::nullopt;
  return r;
}

std::optional<BulkReadRequest> parse_bulk_read(const Packet& packet) {
  if (packet.instruction != Instruction::bulk_read || packet.params.empty() || packet.params.size() % 5 != 0)
    return std::nullopt;
  return BulkReadRequest{packet.params};
}

std::optional<PingReply> parse_ping_reply(const Packet& packet) {
  if (!packet.is_status() || packet.params.size() != 3) return std::nullopt;
  const std::uint8_t* p = packet.params.data();
  return PingReply{packet.id, load_le<std::uint16_t>(p), p[2]};
}

std::optional<ByteView> parse_read_reply(const Packet& packet, std::uint16_t length) {
  if (!packet.is_status() || packet.params.size() != length) return std::nullopt;
  return packet.params;
}

}  // namespace symoro::dynamixel
