// libFuzzer entry point for the DYNAMIXEL Protocol 2.0 decoder. For any input:
// - decoding never crashes, reads out of bounds or throws (the sanitizers watch);
// - the events do not depend on how the bytes are chunked (all at once vs. varying chunks);
// - every decoded packet re-encodes to exactly the bytes it was decoded from, and every request
//   the instruction parsers accept rebuilds, through its builder, to the same bytes;
// - the decoder ends empty after flush().
// A violated property traps, so libFuzzer reports it as a crash.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "symoro/dynamixel/decoder.hpp"
#include "symoro/dynamixel/instructions.hpp"
#include "symoro/dynamixel/packet.hpp"

using namespace symoro::dynamixel;

namespace {

void check(bool ok) {
  if (!ok) __builtin_trap();
}

using Bytes = std::vector<std::uint8_t>;

bool same(ByteView a, ByteView b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i] != b[i]) return false;
  return true;
}

bool valid_ids(ByteView ids) {
  for (std::uint8_t id : ids)
    if (id > kMaxId) return false;
  return true;
}

struct Event {
  DecodeEvent::Kind kind;
  DecodeError error;
  Bytes raw;
  bool operator==(const Event& o) const {
    return kind == o.kind && (kind != DecodeEvent::Kind::error || error == o.error) && raw == o.raw;
  }
};

// The packet's own properties; `input` bounds the views.
void check_packet(const DecodeEvent& e, std::size_t max_length, Bytes& out) {
  const Packet& p = e.packet;
  check(is_valid_id(p.id));
  check(is_known_instruction(static_cast<std::uint8_t>(p.instruction)));
  check(e.raw.size() >= kHeaderSize + 3 && e.raw.size() <= kHeaderSize + max_length);
  check(p.params.size() + kHeaderSize + kCrcSize + 1 <= e.raw.size());

  check(same(encode(p, out), e.raw));

  if (const auto r = parse_read(p)) check(same(encode_read(p.id, r->address, r->length, out), e.raw));
  if (const auto w = parse_write(p)) check(same(encode_write(p.id, w->address, w->data, out), e.raw));
  if (const auto s = parse_sync_read(p); s && p.id == kBroadcastId && valid_ids(s->ids))
    check(same(encode_sync_read(s->address, s->length, s->ids, out), e.raw));
  if (const auto s = parse_sync_write(p); s && p.id == kBroadcastId) {
    Bytes ids, data;
    for (std::size_t i = 0; i < s->count(); ++i) {
      ids.push_back(s->id(i));
      const ByteView d = s->data(i);
      check(d.size() == s->length);
      data.insert(data.end(), d.begin(), d.end());
    }
    if (valid_ids(ids)) check(same(encode_sync_write(s->address, s->length, ids, data, out), e.raw));
  }
  if (const auto b = parse_bulk_read(p); b && p.id == kBroadcastId) {
    std::vector<BulkReadItem> items;
    bool ok = true;
    for (std::size_t i = 0; i < b->count(); ++i) {
      items.push_back(b->item(i));
      ok = ok && items.back().id <= kMaxId;
    }
    if (ok) check(same(encode_bulk_read(items, out), e.raw));
  }
  if (const auto ping = parse_ping_reply(p))
    check(same(encode_ping_reply(p.id, ping->model_number, ping->firmware, out, p.error), e.raw));
  if (const auto data = parse_read_reply(p, static_cast<std::uint16_t>(p.params.size())))
    check(same(encode_status(p.id, p.error, *data, out), e.raw));
}

// Decodes the input in chunks of `chunk(i)` bytes; checks each packet; returns the events.
template <class Chunk>
std::vector<Event> run(const std::uint8_t* data, std::size_t size, std::size_t max_length, Chunk chunk) {
  Decoder dec(max_length);
  Bytes out;
  std::vector<Event> events;
  auto drain = [&] {
    while (DecodeEvent e = dec.next()) {
      check(e.raw.size() >= 1 && e.raw.size() <= size);
      if (e.kind == DecodeEvent::Kind::packet) check_packet(e, max_length, out);
      events.push_back({e.kind, e.error, Bytes(e.raw.begin(), e.raw.end())});
      check(events.size() <= size + 1);
    }
  };
  for (std::size_t i = 0, n = 0; i < size; i += n) {
    n = chunk(i);
    if (n > size - i) n = size - i;
    dec.feed(data + i, n);
    drain();
  }
  dec.flush();
  drain();
  check(dec.buffered() == 0);
  return events;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // Two limits: the default, and a small one that makes bad_length reachable.
  for (std::size_t max_length : {Decoder::kDefaultMaxLength, std::size_t{24}}) {
    const auto whole = run(data, size, max_length, [&](std::size_t) { return size; });
    const auto bytewise = run(data, size, max_length, [](std::size_t) { return std::size_t{1}; });
    const auto varying =
        run(data, size, max_length, [&](std::size_t i) { return std::size_t{1} + (data[i] * 7u + i) % 23; });
    check(whole == bytewise);
    check(whole == varying);
  }
  return 0;
}
