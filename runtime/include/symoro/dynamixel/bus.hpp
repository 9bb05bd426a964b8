// The controller side of a DYNAMIXEL Protocol 2.0 bus: transactions (request, then the status
// packets it asks for) over a SerialPort, each bounded in time.
//
//   SerialPort port("/dev/ttyUSB0", 3'000'000);
//   Bus bus(port);
//   const std::uint8_t ids[] = {2, 3, 4, 5, 6, 7, 8, 9};
//   bus.sync_write(ids, xseries::kGoalCurrent, goal_currents, cycle_deadline);
//   for (const Reply& r : bus.sync_read(ids, 126, 10, cycle_deadline))
//     if (r.has_data()) use(r.get<std::int16_t>(0), r.get<std::int32_t>(2), r.get<std::int32_t>(6));
//
// Every call ends by min(its own timeout, the caller's deadline): a transaction's timeout is
// BusOptions::margin + one status_timeout per expected status packet + the wire time of the bytes
// at the port's rate. A silent, dead or garbling servo costs at most that. Retries (of the failed
// IDs only) start only when a whole new attempt still fits the caller's deadline, so that a 1 kHz
// loop keeps its period. Replies are typed per ID (Outcome); nothing throws for a bus fault, only
// for a broken port (SerialError) or invalid arguments (std::invalid_argument).
//
// After warm-up (the first call of each shape), nothing allocates: the request, the receive
// buffer, the decoder and the replies' data are reused. The Reply views stay valid until the
// next call.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "symoro/dynamixel/control_table.hpp"
#include "symoro/dynamixel/decoder.hpp"
#include "symoro/dynamixel/endian.hpp"
#include "symoro/dynamixel/instructions.hpp"
#include "symoro/dynamixel/packet.hpp"
#include "symoro/dynamixel/serial_port.hpp"
#include "symoro/dynamixel/span.hpp"

namespace symoro::dynamixel {

struct BusOptions {
  // Per expected status packet: the servo's Return Delay Time (0 on a configured bus; the factory
  // 250 = 500 us needs more) plus its processing.
  std::chrono::microseconds status_timeout{500};
  // Per transaction: scheduling and USB-adapter latency.
  std::chrono::microseconds margin{1000};
  // Extra attempts after a timeout, a corrupt reply or a wrong ID (not after an error status: the
  // servo answered). Only when the caller's deadline leaves room for a whole attempt.
  int retries = 1;
};

// What became of one expected status packet.
enum class Outcome : std::uint8_t {
  ok,              // data valid
  hardware_alert,  // data valid, but the alert bit is set: read Hardware Error Status(70)
  error_status,    // the servo refused the instruction: error.number() says why; no data
  timeout,         // nothing (or only its partial reply) arrived before the deadline
  bad_crc,         // its reply failed the CRC check
  corrupt,         // a reply with valid CRC but the wrong size, or undecodable bytes
  wrong_id,        // a status packet from an ID not asked for arrived instead
  not_sent,        // the request could not be written before the deadline
};
const char* to_string(Outcome outcome);

struct Reply {
  std::uint8_t id = 0;
  Outcome outcome = Outcome::timeout;
  StatusError error;  // the status packet's error byte, when one arrived
  ByteView data;      // the parameters read (ping: model number and firmware)

  // Ok or alert: the instruction was carried out (and read data, if any, is valid).
  bool has_data() const { return outcome == Outcome::ok || outcome == Outcome::hardware_alert; }
  // A little-endian field of the data at `offset`; 0 when it does not fit.
  template <class T>
  T get(std::size_t offset = 0) const {
    return offset + sizeof(T) <= data.size() ? load_le<T>(data.data() + offset) : T{0};
  }
};

struct BusStats {
  std::uint64_t transactions = 0;    // calls (a retried call counts once)
  std::uint64_t attempts = 0;        // requests written, retries included
  std::uint64_t retries = 0;         // attempts beyond the first
  std::uint64_t replies_ok = 0;      // ok or hardware_alert
  std::uint64_t timeouts = 0;        // per expected reply, final outcome (after retries)
  std::uint64_t crc_errors = 0;      // per decoded frame, every attempt
  std::uint64_t corrupt = 0;         // per reply or frame, every attempt
  std::uint64_t wrong_ids = 0;       // per stray status packet
  std::uint64_t error_statuses = 0;  // per reply
  std::uint64_t alerts = 0;          // per reply with the alert bit
  std::uint64_t not_sent = 0;        // requests not written before the deadline
};

class Bus {
 public:
  using Clock = SerialPort::Clock;
  static constexpr Clock::time_point kNoDeadline = Clock::time_point::max();

  explicit Bus(SerialPort& port, BusOptions options = {});

  // data = model number (2 bytes) and firmware version.
  Reply ping(std::uint8_t id, Clock::time_point deadline = kNoDeadline);
  // Every servo that answers a broadcast ping within `wait` (there is no count to wait for).
  std::vector<PingReply> ping_all(std::chrono::microseconds wait = std::chrono::milliseconds(20));
  Reply read(std::uint8_t id, std::uint16_t address, std::uint16_t length, Clock::time_point deadline = kNoDeadline);
  Reply read(std::uint8_t id, xseries::Item item, Clock::time_point deadline = kNoDeadline) {
    return read(id, item.address, item.size, deadline);
  }
  // To the broadcast ID: no reply; the outcome is ok when the request was written.
  Reply write(std::uint8_t id, std::uint16_t address, ByteView data, Clock::time_point deadline = kNoDeadline);
  // The value's low item.size bytes (two's complement for signed items).
  Reply write(std::uint8_t id, xseries::Item item, std::int32_t value, Clock::time_point deadline = kNoDeadline);
  // Clears a hardware error (the servo restarts with torque off).
  Reply reboot(std::uint8_t id, Clock::time_point deadline = kNoDeadline);

  // One reply per ID, in the order of `ids` (distinct, 0..252).
  Span<const Reply> sync_read(ByteView ids, std::uint16_t address, std::uint16_t length,
                              Clock::time_point deadline = kNoDeadline);
  // `data`: ids.size() records of `length` bytes. No reply; false when not written in time.
  bool sync_write(ByteView ids, std::uint16_t address, std::uint16_t length, ByteView data,
                  Clock::time_point deadline = kNoDeadline);
  // One value per ID into an item (e.g. Goal Current), packed without allocating.
  bool sync_write(ByteView ids, xseries::Item item, Span<const std::int32_t> values,
                  Clock::time_point deadline = kNoDeadline);
  // One reply per item, in order (distinct IDs).
  Span<const Reply> bulk_read(Span<const BulkReadItem> items, Clock::time_point deadline = kNoDeadline);

  // The timeout of one attempt that writes `request_bytes` and expects `replies` status packets
  // with `reply_params` parameter bytes in all.
  Clock::duration attempt_timeout(std::size_t request_bytes, std::size_t replies, std::size_t reply_params) const;

  const BusStats& stats() const { return stats_; }
  void reset_stats() { stats_ = BusStats{}; }
  const BusOptions& options() const { return options_; }
  void set_options(const BusOptions& options) { options_ = options; }
  SerialPort& port() { return port_; }

 private:
  struct Slot {
    std::uint8_t id = 0;
    std::uint16_t address = 0;  // for re-requesting a bulk read item
    std::uint16_t length = 0;   // expected parameter bytes
    std::size_t data_offset = 0;
    bool resolved = false;
  };

  enum class Kind : std::uint8_t { single, sync_read, bulk_read };

  // Runs attempts for slots_/replies_ (prepared by the caller) until every slot is resolved with
  // a final answer, the retries are used up or the deadline leaves no room.
  void transact(Kind kind, std::uint16_t address, std::uint16_t length, Clock::time_point deadline);
  // One attempt: writes request_ and collects replies for the unresolved slots until `until`.
  void attempt(Clock::time_point until);
  void handle(const DecodeEvent& event);
  // The first unresolved slot whose outcome is still unexplained (an anonymous corrupt frame is
  // most likely its reply), or -1.
  std::size_t first_unexplained() const;
  std::size_t find_unresolved(std::uint8_t id) const;
  void prepare(std::size_t count);
  static bool retryable(Outcome outcome);

  SerialPort& port_;
  BusOptions options_;
  BusStats stats_;
  Decoder decoder_;
  Buffer request_;
  std::vector<std::uint8_t> rx_;
  std::vector<std::uint8_t> data_;  // the replies' parameters, slot by slot
  std::vector<std::uint8_t> packed_;
  std::vector<std::uint8_t> retry_ids_;
  std::vector<BulkReadItem> retry_items_;
  std::vector<Slot> slots_;
  std::vector<Reply> replies_;
  std::size_t pending_ = 0;          // unresolved slots in the current attempt
  std::size_t expected_params_ = 0;  // for the current attempt's timeout
};

}  // namespace symoro::dynamixel
