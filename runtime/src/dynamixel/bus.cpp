#include "symoro/dynamixel/bus.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace symoro::dynamixel {
namespace {

constexpr std::size_t kNone = static_cast<std::size_t>(-1);
// A status packet without parameters: header 4, ID, Length 2, instruction, error, CRC 2.
constexpr std::size_t kStatusOverhead = 11;
constexpr std::size_t kReceiveChunk = 512;

void check_distinct(ByteView ids, const char* what) {
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] > kMaxId)
      throw std::invalid_argument(std::string("DYNAMIXEL bus ") + what + ": ID " + std::to_string(ids[i]) +
                                  " is not 0..252");
    for (std::size_t j = 0; j < i; ++j)
      if (ids[j] == ids[i])  // replies are matched by ID: a duplicate would be ambiguous
        throw std::invalid_argument(std::string("DYNAMIXEL bus ") + what + ": ID " + std::to_string(ids[i]) +
                                    " listed twice");
  }
}

void check_unicast(std::uint8_t id, const char* what) {
  if (id > kMaxId)
    throw std::invalid_argument(std::string("DYNAMIXEL bus ") + what + ": ID " + std::to_string(id) + " is not 0..252");
}

}  // namespace

const char* to_string(Outcome outcome) {
  switch (outcome) {
    case Outcome::ok:
      return "ok";
    case Outcome::hardware_alert:
      return "hardware alert";
    case Outcome::error_status:
      return "error status";
    case Outcome::timeout:
      return "timeout";
    case Outcome::bad_crc:
      return "bad CRC";
    case Outcome::corrupt:
      return "corrupt reply";
    case Outcome::wrong_id:
      return "wrong ID";
    case Outcome::not_sent:
      return "request not sent";
  }
  return "unknown outcome";
}

Bus::Bus(SerialPort& port, BusOptions options) : port_(port), options_(options) {
  rx_.resize(kReceiveChunk);
  request_.reserve(256);
  slots_.reserve(16);
  replies_.reserve(16);
  data_.reserve(256);
  packed_.reserve(64);
  retry_ids_.reserve(16);
  retry_items_.reserve(16);
}

Bus::Clock::duration Bus::attempt_timeout(std::size_t request_bytes, std::size_t replies,
                                          std::size_t reply_params) const {
  return options_.margin + options_.status_timeout * static_cast<long>(replies) +
         port_.transmit_time(request_bytes + replies * kStatusOverhead + reply_params);
}

bool Bus::retryable(Outcome outcome) {
  return outcome == Outcome::timeout || outcome == Outcome::bad_crc || outcome == Outcome::corrupt ||
         outcome == Outcome::wrong_id || outcome == Outcome::not_sent;
}

void Bus::prepare(std::size_t count) {
  slots_.resize(count);
  replies_.resize(count);
  for (std::size_t i = 0; i < count; ++i) {
    slots_[i] = Slot{};
    replies_[i] = Reply{};
  }
}

std::size_t Bus::find_unresolved(std::uint8_t id) const {
  for (std::size_t i = 0; i < slots_.size(); ++i)
    if (!slots_[i].resolved && slots_[i].id == id) return i;
  return kNone;
}

std::size_t Bus::first_unexplained() const {
  for (std::size_t i = 0; i < slots_.size(); ++i)
    if (!slots_[i].resolved && replies_[i].outcome == Outcome::timeout) return i;
  return kNone;
}

void Bus::handle(const DecodeEvent& event) {
  if (event.kind == DecodeEvent::Kind::packet) {
    // Not a status: our own request echoed by an adapter without echo cancellation.
    if (!event.packet.is_status()) return;
    const std::size_t i = find_unresolved(event.packet.id);
    if (i == kNone) {
      // A servo that was not asked (two servos sharing an ID, a misconfigured ID) or a late
      // duplicate: it explains why the next expected reply is missing.
      ++stats_.wrong_ids;
      const std::size_t k = first_unexplained();
      if (k != kNone) replies_[k].outcome = Outcome::wrong_id;
      return;
    }
    Slot& slot = slots_[i];
    Reply& reply = replies_[i];
    slot.resolved = true;
    --pending_;
    reply.error = event.packet.status_error();
    reply.data = ByteView();
    if (!reply.error.ok()) {
      reply.outcome = Outcome::error_status;
    } else if (event.packet.params.size() != slot.length) {
      reply.outcome = Outcome::corrupt;
      ++stats_.corrupt;
    } else {
      std::copy(event.packet.params.begin(), event.packet.params.end(),
                data_.begin() + static_cast<std::ptrdiff_t>(slot.data_offset));
      reply.data = ByteView(data_.data() + slot.data_offset, slot.length);
      reply.outcome = reply.error.alert() ? Outcome::hardware_alert : Outcome::ok;
    }
    return;
  }
  // A rejected frame. Its ID byte is untrusted, but when it names a servo still expected it is
  // almost surely that servo's reply: resolving it now ends the transaction without waiting for
  // the deadline. Otherwise it explains the first reply still missing.
  const bool crc = event.error == DecodeError::bad_crc;
  ++(crc ? stats_.crc_errors : stats_.corrupt);
  const Outcome outcome = crc ? Outcome::bad_crc : Outcome::corrupt;
  std::size_t k = event.raw.size() > 4 ? find_unresolved(event.raw[4]) : kNone;
  if (k != kNone &&
      (crc || event.error == DecodeError::bad_stuffing || event.error == DecodeError::unknown_instruction)) {
    slots_[k].resolved = true;
    --pending_;
    replies_[k].outcome = outcome;
    return;
  }
  if (k == kNone) k = first_unexplained();
  if (k != kNone) replies_[k].outcome = outcome;
}

void Bus::attempt(Clock::time_point until) {
  ++stats_.attempts;
  pending_ = 0;
  for (const Slot& s : slots_) pending_ += s.resolved ? 0 : 1;
  // A reply that came after an earlier timeout must not be taken for this request's.
  port_.flush_input();
  decoder_.reset();
  if (!port_.write_all(request_, until)) {
    for (std::size_t i = 0; i < slots_.size(); ++i)
      if (!slots_[i].resolved) replies_[i].outcome = Outcome::not_sent;
    ++stats_.not_sent;
    return;
  }
  while (pending_ > 0) {
    const std::size_t n = port_.read_some(rx_, until);
    if (n == 0) break;
    decoder_.feed(rx_.data(), n);
    while (pending_ > 0) {
      const DecodeEvent e = decoder_.next();
      if (!e) break;
      handle(e);
    }
  }
  if (pending_ > 0) {  // deadline: a partial reply is a truncated (corrupt) one
    decoder_.flush();
    while (pending_ > 0) {
      const DecodeEvent e = decoder_.next();
      if (!e) break;
      handle(e);
    }
  }
}

void Bus::transact(Kind kind, std::uint16_t address, std::uint16_t length, Clock::time_point deadline) {
  ++stats_.transactions;
  int attempts_left = 1 + std::max(0, options_.retries);
  for (bool first = true;; first = false) {
    std::size_t replies = 0, params = 0;
    for (const Slot& s : slots_)
      if (!s.resolved) {
        ++replies;
        params += s.length;
      }
    const Clock::duration timeout = attempt_timeout(request_.size(), replies, params);
    const Clock::time_point now = Clock::now();
    if (!first) {
      if (now + timeout > deadline) break;  // no room for a whole attempt: keep the period
      ++stats_.retries;
    }
    attempt(deadline - now < timeout ? deadline : now + timeout);
    if (--attempts_left <= 0) break;

    // Retry only the failures that another attempt may fix.
    bool again = false;
    for (std::size_t i = 0; i < slots_.size(); ++i) {
      const bool retry = retryable(replies_[i].outcome);
      slots_[i].resolved = !retry;
      if (retry) {
        replies_[i] = Reply();
        replies_[i].id = slots_[i].id;
      }
      again = again || retry;
    }
    if (!again) break;
    if (kind == Kind::sync_read) {
      retry_ids_.clear();
      for (const Slot& s : slots_)
        if (!s.resolved) retry_ids_.push_back(s.id);
      encode_sync_read(address, length, retry_ids_, request_);
    } else if (kind == Kind::bulk_read) {
      retry_items_.clear();
      for (const Slot& s : slots_)
        if (!s.resolved) retry_items_.push_back(BulkReadItem{s.id, s.address, s.length});
      encode_bulk_read(Span<const BulkReadItem>(retry_items_.data(), retry_items_.size()), request_);
    }  // a single transaction re-sends request_ as it is
  }
  for (const Reply& r : replies_) {
    switch (r.outcome) {
      case Outcome::ok:
        ++stats_.replies_ok;
        break;
      case Outcome::hardware_alert:
        ++stats_.replies_ok;
        ++stats_.alerts;
        break;
      case Outcome::error_status:
        ++stats_.error_statuses;
        if (r.error.alert()) ++stats_.alerts;
        break;
      case Outcome::timeout:
        ++stats_.timeouts;
        break;
      default:
        break;
    }
  }
}

Reply Bus::ping(std::uint8_t id, Clock::time_point deadline) {
  check_unicast(id, "ping");
  prepare(1);
  slots_[0].id = id;
  slots_[0].length = 3;
  replies_[0].id = id;
  data_.resize(3);
  encode_ping(id, request_);
  transact(Kind::single, 0, 0, deadline);
  return replies_[0];
}

std::vector<PingReply> Bus::ping_all(std::chrono::microseconds wait) {
  std::vector<PingReply> found;
  ++stats_.transactions;
  ++stats_.attempts;
  port_.flush_input();
  decoder_.reset();
  encode_ping(kBroadcastId, request_);
  const Clock::time_point until = Clock::now() + wait;
  if (!port_.write_all(request_, until)) {
    ++stats_.not_sent;
    return found;
  }
  for (;;) {
    const std::size_t n = port_.read_some(rx_, until);
    if (n == 0) break;
    decoder_.feed(rx_.data(), n);
    while (const DecodeEvent e = decoder_.next()) {
      if (e.kind == DecodeEvent::Kind::error) {
        ++(e.error == DecodeError::bad_crc ? stats_.crc_errors : stats_.corrupt);
      } else if (const auto reply = parse_ping_reply(e.packet)) {
        ++stats_.replies_ok;
        found.push_back(*reply);
      }
    }
  }
  return found;
}

Reply Bus::read(std::uint8_t id, std::uint16_t address, std::uint16_t length, Clock::time_point deadline) {
  check_unicast(id, "read");
  prepare(1);
  slots_[0].id = id;
  slots_[0].address = address;
  slots_[0].length = length;
  replies_[0].id = id;
  data_.resize(length);
  encode_read(id, address, length, request_);
  transact(Kind::single, address, length, deadline);
  return replies_[0];
}

Reply Bus::write(std::uint8_t id, std::uint16_t address, ByteView data, Clock::time_point deadline) {
  encode_write(id, address, data, request_);
  if (id == kBroadcastId) {  // every servo applies it, none answers
    ++stats_.transactions;
    ++stats_.attempts;
    const Clock::time_point now = Clock::now();
    const Clock::duration timeout = attempt_timeout(request_.size(), 0, 0);
    Reply r;
    r.id = id;
    r.outcome = port_.write_all(request_, deadline - now < timeout ? deadline : now + timeout) ? Outcome::ok
                                                                                               : Outcome::not_sent;
    if (r.outcome == Outcome::not_sent) ++stats_.not_sent;
    return r;
  }
  check_unicast(id, "write");
  prepare(1);
  slots_[0].id = id;
  replies_[0].id = id;
  data_.clear();
  transact(Kind::single, address, 0, deadline);
  return replies_[0];
}

Reply Bus::write(std::uint8_t id, xseries::Item item, std::int32_t value, Clock::time_point deadline) {
  std::uint8_t bytes[4];
  store_le(bytes, value);
  return write(id, item.address, ByteView(bytes, item.size), deadline);
}

Reply Bus::reboot(std::uint8_t id, Clock::time_point deadline) {
  check_unicast(id, "reboot");
  prepare(1);
  slots_[0].id = id;
  replies_[0].id = id;
  data_.clear();
  PacketWriter(request_, id, Instruction::reboot).finish();
  transact(Kind::single, 0, 0, deadline);
  return replies_[0];
}

Span<const Reply> Bus::sync_read(ByteView ids, std::uint16_t address, std::uint16_t length,
                                 Clock::time_point deadline) {
  check_distinct(ids, "sync read");
  prepare(ids.size());
  data_.resize(ids.size() * length);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    slots_[i].id = ids[i];
    slots_[i].address = address;
    slots_[i].length = length;
    slots_[i].data_offset = i * length;
    replies_[i].id = ids[i];
  }
  encode_sync_read(address, length, ids, request_);
  transact(Kind::sync_read, address, length, deadline);
  return Span<const Reply>(replies_.data(), replies_.size());
}

bool Bus::sync_write(ByteView ids, std::uint16_t address, std::uint16_t length, ByteView data,
                     Clock::time_point deadline) {
  check_distinct(ids, "sync write");
  encode_sync_write(address, length, ids, data, request_);
  ++stats_.transactions;
  ++stats_.attempts;
  const Clock::time_point now = Clock::now();
  const Clock::duration timeout = attempt_timeout(request_.size(), 0, 0);
  // Not flushed: no reply is expected, and the next transaction flushes before it writes.
  if (port_.write_all(request_, deadline - now < timeout ? deadline : now + timeout)) return true;
  ++stats_.not_sent;
  return false;
}

bool Bus::sync_write(ByteView ids, xseries::Item item, Span<const std::int32_t> values, Clock::time_point deadline) {
  if (values.size() != ids.size())
    throw std::invalid_argument("DYNAMIXEL bus sync write: " + std::to_string(values.size()) + " values for " +
                                std::to_string(ids.size()) + " IDs");
  packed_.resize(ids.size() * item.size);
  for (std::size_t i = 0; i < values.size(); ++i) {
    std::uint8_t bytes[4];
    store_le(bytes, values[i]);
    std::copy(bytes, bytes + item.size, packed_.begin() + static_cast<std::ptrdiff_t>(i * item.size));
  }
  return sync_write(ids, item.address, item.size, packed_, deadline);
}

Span<const Reply> Bus::bulk_read(Span<const BulkReadItem> items, Clock::time_point deadline) {
  std::size_t total = 0;
  for (std::size_t i = 0; i < items.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j)
      if (items[j].id == items[i].id)
        throw std::invalid_argument("DYNAMIXEL bus bulk read: ID " + std::to_string(items[i].id) + " listed twice");
    total += items[i].length;
  }
  prepare(items.size());
  data_.resize(total);
  std::size_t offset = 0;
  for (std::size_t i = 0; i < items.size(); ++i) {
    slots_[i].id = items[i].id;
    slots_[i].address = items[i].address;
    slots_[i].length = items[i].length;
    slots_[i].data_offset = offset;
    offset += items[i].length;
    replies_[i].id = items[i].id;
  }
  encode_bulk_read(items, request_);
  transact(Kind::bulk_read, 0, 0, deadline);
  return Span<const Reply>(replies_.data(), replies_.size());
}

}  // namespace symoro::dynamixel
