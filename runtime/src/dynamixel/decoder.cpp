#include "symoro/dynamixel/decoder.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "symoro/dynamixel/crc.hpp"
#include "symoro/dynamixel/endian.hpp"

namespace symoro::dynamixel {
namespace {

constexpr std::size_t kMinLength = 3;  // instruction + CRC

// First index in [from, to) where the 4-byte header starts with all 4 bytes before `to`, or `to`.
std::size_t find_header(const std::uint8_t* data, std::size_t from, std::size_t to) {
  for (std::size_t i = from; i + 4 <= to; ++i)
    if (data[i] == 0xFF && data[i + 1] == 0xFF && data[i + 2] == 0xFD && data[i + 3] == 0x00) return i;
  return to;
}

// Whether the bytes [at, end), fewer than 4, are the beginning of a header.
bool header_prefix(const std::uint8_t* data, std::size_t at, std::size_t end) {
  for (std::size_t i = at; i < end; ++i)
    if (data[i] != kHeader[i - at]) return false;
  return true;
}

}  // namespace

const char* to_string(DecodeError error) {
  switch (error) {
    case DecodeError::bad_id:
      return "invalid packet ID";
    case DecodeError::bad_length:
      return "invalid packet length";
    case DecodeError::bad_crc:
      return "CRC mismatch";
    case DecodeError::truncated:
      return "truncated packet";
    case DecodeError::bad_stuffing:
      return "invalid byte stuffing";
    case DecodeError::unknown_instruction:
      return "unknown instruction";
  }
  return "unknown decode error";
}

Decoder::Decoder(std::size_t max_length) : max_length_(max_length) {
  if (max_length < kMinLength + 1 || max_length > 0xFFFF)
    throw std::invalid_argument("DYNAMIXEL decoder: max_length " + std::to_string(max_length) + " is not in 4..65535");
  buffer_.reserve(kHeaderSize + max_length + 256);
  region_.reserve(max_length);
}

void Decoder::reset() {
  buffer_.clear();
  begin_ = 0;
  region_.clear();
  skipped_ = 0;
  flushing_ = false;
}

void Decoder::feed(ByteView bytes) {
  if (bytes.empty()) return;
  if (begin_ > 0) {  // drop what was consumed before growing
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(begin_));
    begin_ = 0;
  }
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
}

DecodeEvent Decoder::reject(DecodeError error, std::size_t frame, std::size_t size) {
  DecodeEvent e;
  e.kind = DecodeEvent::Kind::error;
  e.error = error;
  e.raw = ByteView(buffer_.data() + frame, size);
  e.skipped = skipped_;
  skipped_ = 0;
  begin_ = frame + 1;  // resynchronize from the byte after the rejected header
  return e;
}

bool Decoder::unstuff(std::size_t frame, std::size_t region_size) {
  region_.clear();
  const std::uint8_t* p = buffer_.data() + frame + kHeaderSize;
  int ff_run = 0;
  for (std::size_t i = 0; i < region_size; ++i) {
    const std::uint8_t b = p[i];
    region_.push_back(b);
    if (b == 0xFD && ff_run == 2) {
      if (i + 1 >= region_size || p[i + 1] != 0xFD) return false;
      ++i;  // the stuffing byte
      ff_run = 0;
    } else {
      ff_run = b == 0xFF ? std::min(ff_run + 1, 2) : 0;
    }
  }
  return true;
}

DecodeEvent Decoder::next() {
  const std::uint8_t* data = buffer_.data();
  const std::size_t end = buffer_.size();

  // 1. Hunt for a header; keep a tail that may be the start of one.
  const std::size_t frame = find_header(data, begin_, end);
  if (frame == end) {
    const std::size_t keep = flushing_ ? 0 : std::min<std::size_t>(3, end - begin_);
    skipped_ += end - begin_ - keep;
    begin_ = end - keep;
    flushing_ = false;
    if (keep == 0) {  // empty: restart at the front so that feed() never has to move bytes
      buffer_.clear();
      begin_ = 0;
    }
    return DecodeEvent{};
  }
  skipped_ += frame - begin_;
  begin_ = frame;

  // 2. ID and Length.
  const std::size_t available = end - frame;
  if (available < kHeaderSize) {
    if (flushing_) return reject(DecodeError::truncated, frame, available);
    return DecodeEvent{};
  }
  const std::uint8_t id = data[frame + 4];
  if (!is_valid_id(id)) return reject(DecodeError::bad_id, frame, kHeaderSize);
  const std::size_t length = load_le<std::uint16_t>(data + frame + 5);
  if (length < kMinLength || length > max_length_) return reject(DecodeError::bad_length, frame, kHeaderSize);
  const std::size_t size = kHeaderSize + length;
  const std::size_t region_end = frame + size - kCrcSize;

  // 3. A header entirely inside the stuffed region cannot belong to this packet (stuffing forbids
  //    FF FF FD there): this packet was cut off and a new one began. Checked before waiting for
  //    the rest, so that the new packet is not held back, and before the CRC, so that the result
  //    does not depend on how the bytes were chunked.
  const std::size_t scan_to = std::min(end, region_end);
  const std::size_t inner = find_header(data, frame + kHeaderSize, scan_to);
  if (inner != scan_to) return reject(DecodeError::truncated, frame, inner - frame);
  if (available < size) {
    if (flushing_) return reject(DecodeError::truncated, frame, available);
    return DecodeEvent{};
  }

  // 4. CRC over the stuffed bytes. On a mismatch, a header starting inside the frame (it may run
  //    past the frame's end) means the packet was cut off; when the frame ends with the beginning
  //    of a header, wait for up to 3 more bytes to tell, so that chunking cannot change the answer.
  const std::uint16_t crc = crc16(data + frame, size - kCrcSize);
  if (crc != load_le<std::uint16_t>(data + frame + size - kCrcSize)) {
    const std::size_t frame_end = frame + size;
    if (!flushing_ && end < frame_end + 3)
      for (std::size_t k = frame_end - 3; k < frame_end; ++k)
        if (end < k + 4 && header_prefix(data, k, end)) return DecodeEvent{};
    const std::size_t probe_end = std::min(end, frame_end + 3);
    const std::size_t next = find_header(data, frame + 1, probe_end);
    if (next < frame_end) return reject(DecodeError::truncated, frame, next - frame);
    return reject(DecodeError::bad_crc, frame, size);
  }

  // 5. A genuine frame from here on: consume it whole whatever its content.
  DecodeEvent e;
  e.raw = ByteView(data + frame, size);
  e.skipped = skipped_;
  skipped_ = 0;
  begin_ = frame + size;
  e.kind = DecodeEvent::Kind::error;
  e.packet.id = id;
  e.packet.instruction = static_cast<Instruction>(data[frame + kHeaderSize]);
  if (!unstuff(frame, length - kCrcSize)) {
    e.error = DecodeError::bad_stuffing;
    return e;
  }
  if (!is_known_instruction(region_[0])) {
    e.error = DecodeError::unknown_instruction;
    return e;
  }
  std::size_t params = 1;
  if (e.packet.is_status()) {
    if (region_.size() < 2) {
      e.error = DecodeError::bad_length;
      return e;
    }
    e.packet.error = region_[1];
    params = 2;
  }
  e.packet.params = ByteView(region_.data() + params, region_.size() - params);
  e.kind = DecodeEvent::Kind::packet;
  return e;
}

}  // namespace symoro::dynamixel
