// Builders and parsers of the Protocol 2.0 instructions a controller and a (virtual) servo
// exchange: Ping, Read, Write, Sync Read, Sync Write, Bulk Read, and their status replies.
// Parameter layouts from the e-manual, https://emanual.robotis.com/docs/en/dxl/protocol2/
// ("Instruction Details"); addresses and lengths are 16-bit little endian.
//
// Builders (encode_*: plain read/write here would hide POSIX ::read/::write in this namespace)
// write a whole packet into `out` (cleared; reuse it, and nothing allocates once its
// capacity suffices) and return a view of it. They throw std::invalid_argument on inconsistent
// arguments (an invalid ID, data of the wrong size) and std::length_error when the packet does
// not fit the 16-bit Length. Parsers return std::nullopt when the packet has another instruction
// or parameters of another size; their views point into the packet's parameters.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "symoro/dynamixel/endian.hpp"
#include "symoro/dynamixel/packet.hpp"
#include "symoro/dynamixel/span.hpp"

namespace symoro::dynamixel {

using Buffer = std::vector<std::uint8_t>;

// ---- Controller side: instruction packets ------------------------------------------------------

ByteView encode_ping(std::uint8_t id, Buffer& out);
ByteView encode_read(std::uint8_t id, std::uint16_t address, std::uint16_t length, Buffer& out);
ByteView encode_write(std::uint8_t id, std::uint16_t address, ByteView data, Buffer& out);
// The same item of every listed servo; each answers with its own status packet, in list order.
ByteView encode_sync_read(std::uint16_t address, std::uint16_t length, ByteView ids, Buffer& out);
// `data` holds ids.size() records of `length` bytes, in the order of `ids`.
ByteView encode_sync_write(std::uint16_t address, std::uint16_t length, ByteView ids, ByteView data, Buffer& out);

struct BulkReadItem {
  std::uint8_t id = 0;
  std::uint16_t address = 0;
  std::uint16_t length = 0;
};
ByteView encode_bulk_read(Span<const BulkReadItem> items, Buffer& out);

// ---- Servo side: status packets ----------------------------------------------------------------

ByteView encode_status(std::uint8_t id, std::uint8_t error, ByteView params, Buffer& out);
ByteView encode_ping_reply(std::uint8_t id, std::uint16_t model_number, std::uint8_t firmware, Buffer& out,
                           std::uint8_t error = 0);

// ---- Parsing requests (servo side) -------------------------------------------------------------

struct ReadRequest {
  std::uint16_t address = 0;
  std::uint16_t length = 0;
};
std::optional<ReadRequest> parse_read(const Packet& packet);

struct WriteRequest {
  std::uint16_t address = 0;
  ByteView data;
};
std::optional<WriteRequest> parse_write(const Packet& packet);

struct SyncReadRequest {
  std::uint16_t address = 0;
  std::uint16_t length = 0;
  ByteView ids;
};
std::optional<SyncReadRequest> parse_sync_read(const Packet& packet);

struct SyncWriteRequest {
  std::uint16_t address = 0;
  std::uint16_t length = 0;
  ByteView records;  // count() records of 1 + length bytes: ID then data

  std::size_t count() const { return records.size() / (std::size_t{length} + 1); }
  std::uint8_t id(std::size_t i) const { return records[i * (std::size_t{length} + 1)]; }
  ByteView data(std::size_t i) const { return records.subspan(i * (std::size_t{length} + 1) + 1, length); }
};
// Requires at least one record and no partial one.
std::optional<SyncWriteRequest> parse_sync_write(const Packet& packet);

struct BulkReadRequest {
  ByteView records;  // count() records of 5 bytes: ID, address, length

  std::size_t count() const { return records.size() / 5; }
  BulkReadItem item(std::size_t i) const {
    const std::uint8_t* r = records.data() + 5 * i;
    return BulkReadItem{r[0], load_le<std::uint16_t>(r + 1), load_le<std::uint16_t>(r + 3)};
  }
};
std::optional<BulkReadRequest> parse_bulk_read(const Packet& packet);

// ---- Parsing replies (controller side) ---------------------------------------------------------

struct PingReply {
  std::uint8_t id = 0;
  std::uint16_t model_number = 0;
  std::uint8_t firmware = 0;
};
// A status packet with the 3 ping parameters (model number, firmware version).
std::optional<PingReply> parse_ping_reply(const Packet& packet);

// The data of a Read, Sync Read or Bulk Read reply: a status packet with `length` parameters.
// A servo that reports an error may send none; check packet.status_error() first.
std::optional<ByteView> parse_read_reply(const Packet& packet, std::uint16_t length);

}  // namespace symoro::dynamixel
