// A streaming decoder of Protocol 2.0 packets (status packets, and instruction packets for the
// servo side). Bytes arrive in arbitrary chunks (a serial port's reads); the decoder hunts for the
// header FF FF FD 00, waits for the Length announced, checks the CRC over the stuffed bytes, then
// removes the stuffing (e-manual, Protocol 2.0, "Processing Order of Reception",
// https://emanual.robotis.com/docs/en/dxl/protocol2/).
//
//   Decoder dec;
//   dec.feed(chunk);
//   while (DecodeEvent e = dec.next()) { if (e.kind == DecodeEvent::Kind::packet) use(e.packet); }
//
// A frame rejected for its ID, Length, CRC or truncation costs only its first byte: scanning
// restarts one byte after the rejected header, so a good packet hidden behind garbage or a
// cut-off packet is still found. A frame whose CRC is correct is consumed whole, even when its
// content is invalid (unknown instruction, bad stuffing). The events do not depend on how the
// input is chunked. Nothing allocates once the buffers have grown to the largest chunk plus one
// packet.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "symoro/dynamixel/packet.hpp"
#include "symoro/dynamixel/span.hpp"

namespace symoro::dynamixel {

enum class DecodeError : std::uint8_t {
  bad_id,               // ID 253 or 255 after a header
  bad_length,           // Length below the minimum (3; 4 for a status) or above the decoder's limit
  bad_crc,              // CRC mismatch
  truncated,            // the packet was cut off: a new header began inside it, or the input ended
  bad_stuffing,         // FF FF FD inside the region not followed by the stuffing byte FD
  unknown_instruction,  // well-formed (CRC ok) but an instruction the protocol does not define
};
const char* to_string(DecodeError error);

struct DecodeEvent {
  enum class Kind : std::uint8_t { none, packet, error };
  Kind kind = Kind::none;
  DecodeError error = DecodeError::bad_crc;  // when kind == error
  // When kind == packet; for unknown_instruction and bad_stuffing errors, id and instruction.
  Packet packet;
  // The frame's wire bytes from its header: the whole packet, or what was rejected (for bad_id
  // and bad_length the 7 header bytes; for truncated the bytes before the header that cut it
  // off, or what had arrived before flush()).
  ByteView raw;
  // Bytes discarded while searching for a header since the previous event.
  std::size_t skipped = 0;

  explicit operator bool() const { return kind != Kind::none; }
};

class Decoder {
 public:
  // The largest Length field accepted; a larger one is rejected as bad_length at once instead of
  // waiting for up to 64 KiB. The default fits any packet a CRANE-X7 cycle exchanges.
  static constexpr std::size_t kDefaultMaxLength = 1024;
  explicit Decoder(std::size_t max_length = kDefaultMaxLength);

  void feed(ByteView bytes);
  void feed(const std::uint8_t* data, std::size_t size) { feed(ByteView(data, size)); }
  // The next packet or error; kind none when more bytes are needed. The event's views stay valid
  // until the next call of feed(), next(), flush() or reset().
  DecodeEvent next();
  // No more bytes will come for what is buffered (end of input, or a reply timeout): the next()
  // calls that follow report a pending partial packet as truncated and drain the buffer; once
  // next() returns none, the decoder is empty and takes new input normally.
  void flush() { flushing_ = true; }
  void reset();

  std::size_t max_length() const { return max_length_; }
  std::size_t buffered() const { return buffer_.size() - begin_; }

 private:
  DecodeEvent reject(DecodeError error, std::size_t frame, std::size_t size);
  // Unstuffs the region of the frame at `frame` into region_; false on invalid stuffing.
  bool unstuff(std::size_t frame, std::size_t region_size);

  std::size_t max_length_;
  std::vector<std::uint8_t> buffer_;  // received bytes; [begin_, end) not yet consumed
  std::size_t begin_ = 0;
  std::vector<std::uint8_t> region_;  // the last packet's unstuffed instruction..parameters
  std::size_t skipped_ = 0;
  bool flushing_ = false;
};

}  // namespace symoro::dynamixel
