// DYNAMIXEL Protocol 2.0: CRC, packet encoding with byte stuffing, the streaming decoder and the
// instruction builders/parsers, against the example packets of the ROBOTIS e-manual
// (https://emanual.robotis.com/docs/en/dxl/protocol2/, "Instruction Details"; every byte below
// is copied from there) and against independent reference computations.
#include <symoro/dynamixel/control_table.hpp>
#include <symoro/dynamixel/crc.hpp>
#include <symoro/dynamixel/decoder.hpp>
#include <symoro/dynamixel/endian.hpp>
#include <symoro/dynamixel/instructions.hpp>
#include <symoro/dynamixel/packet.hpp>

#include <cmath>
#include <cstdint>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace symoro::dynamixel {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes hex(const std::string& text) {
  Bytes out;
  std::istringstream in(text);
  std::string token;
  while (in >> token) out.push_back(static_cast<std::uint8_t>(std::stoul(token, nullptr, 16)));
  return out;
}

Bytes copy(ByteView v) { return Bytes(v.begin(), v.end()); }

// An example of the e-manual with the fields it describes.
struct Example {
  const char* name;
  const char* wire;
  std::uint8_t id;
  Instruction instruction;
  std::uint8_t error;
  const char* params;
};

const std::vector<Example>& examples() {
  static const std::vector<Example> e = {
      {"ping", "FF FF FD 00 01 03 00 01 19 4E", 1, Instruction::ping, 0, ""},
      {"ping status ID 1", "FF FF FD 00 01 07 00 55 00 06 04 26 65 5D", 1, Instruction::status, 0, "06 04 26"},
      {"broadcast ping", "FF FF FD 00 FE 03 00 01 31 42", 0xFE, Instruction::ping, 0, ""},
      {"ping status ID 2", "FF FF FD 00 02 07 00 55 00 06 04 26 6F 6D", 2, Instruction::status, 0, "06 04 26"},
      {"read", "FF FF FD 00 01 07 00 02 84 00 04 00 1D 15", 1, Instruction::read, 0, "84 00 04 00"},
      {"read status", "FF FF FD 00 01 08 00 55 00 A6 00 00 00 8C C0", 1, Instruction::status, 0, "A6 00 00 00"},
      {"write", "FF FF FD 00 01 09 00 03 74 00 00 02 00 00 CA 89", 1, Instruction::write, 0, "74 00 00 02 00 00"},
      {"write status", "FF FF FD 00 01 04 00 55 00 A1 0C", 1, Instruction::status, 0, ""},
      {"reg write", "FF FF FD 00 01 09 00 04 68 00 C8 00 00 00 AE 8E", 1, Instruction::reg_write, 0,
       "68 00 C8 00 00 00"},
      {"action", "FF FF FD 00 01 03 00 05 02 CE", 1, Instruction::action, 0, ""},
      {"factory reset", "FF FF FD 00 01 04 00 06 01 A1 E6", 1, Instruction::factory_reset, 0, "01"},
      {"reboot", "FF FF FD 00 01 03 00 08 2F 4E", 1, Instruction::reboot, 0, ""},
      {"clear", "FF FF FD 00 01 08 00 10 01 44 58 4C 22 B1 DC", 1, Instruction::clear, 0, "01 44 58 4C 22"},
      {"sync read", "FF FF FD 00 FE 09 00 82 84 00 04 00 01 02 CE FA", 0xFE, Instruction::sync_read, 0,
       "84 00 04 00 01 02"},
      {"sync read status ID 1", "FF FF FD 00 01 08 00 55 00 A6 00 00 00 8C C0", 1, Instruction::status, 0,
       "A6 00 00 00"},
      {"sync read status ID 2", "FF FF FD 00 02 08 00 55 00 1F 08 00 00 BA BE", 2, Instruction::status, 0,
       "1F 08 00 00"},
      {"sync write", "FF FF FD 00 FE 11 00 83 74 00 04 00 01 96 00 00 00 02 AA 00 00 00 82 87", 0xFE,
       Instruction::sync_write, 0, "74 00 04 00 01 96 00 00 00 02 AA 00 00 00"},
      {"bulk read", "FF FF FD 00 FE 0D 00 92 01 90 00 02 00 02 92 00 01 00 1A 05", 0xFE, Instruction::bulk_read, 0,
       "01 90 00 02 00 02 92 00 01 00"},
      {"bulk read status ID 1", "FF FF FD 00 01 06 00 55 00 77 00 C3 69", 1, Instruction::status, 0, "77 00"},
      {"bulk read status ID 2", "FF FF FD 00 02 05 00 55 00 24 8B A9", 2, Instruction::status, 0, "24"},
      {"bulk write", "FF FF FD 00 FE 10 00 93 01 20 00 02 00 A0 00 02 1F 00 01 00 50 B7 68", 0xFE,
       Instruction::bulk_write, 0, "01 20 00 02 00 A0 00 02 1F 00 01 00 50"},
  };
  return e;
}

// The second CRC algorithm: bit by bit, straight from the polynomial.
std::uint16_t crc_bitwise(const std::uint8_t* data, std::size_t size) {
  std::uint16_t crc = 0;
  for (std::size_t i = 0; i < size; ++i) {
    for (int bit = 7; bit >= 0; --bit) {
      const bool in = ((data[i] >> bit) & 1) != 0;
      const bool top = (crc & 0x8000) != 0;
      crc = static_cast<std::uint16_t>(crc << 1);
      if (in != top) crc ^= 0x8005;
    }
  }
  return crc;
}

// Decodes everything (feeding `chunks` of the input at a time, 0 = all at once) and flushes.
struct Outcome {
  DecodeEvent::Kind kind;
  DecodeError error;
  Bytes raw;
  std::size_t skipped;
};
std::vector<Outcome> decode_all(const Bytes& input, std::mt19937* chunk_rng = nullptr, std::size_t fixed_chunk = 0,
                                std::size_t max_length = Decoder::kDefaultMaxLength) {
  Decoder dec(max_length);
  std::vector<Outcome> out;
  auto drain = [&] {
    while (DecodeEvent e = dec.next()) out.push_back({e.kind, e.error, copy(e.raw), e.skipped});
  };
  std::size_t i = 0;
  while (i < input.size()) {
    std::size_t n = input.size() - i;
    if (fixed_chunk) n = std::min(n, fixed_chunk);
    if (chunk_rng) n = std::min(n, std::uniform_int_distribution<std::size_t>(1, 40)(*chunk_rng));
    dec.feed(input.data() + i, n);
    i += n;
    drain();
  }
  dec.flush();
  drain();
  EXPECT_EQ(dec.buffered(), 0u);
  return out;
}

std::vector<Bytes> packets_of(const std::vector<Outcome>& events) {
  std::vector<Bytes> p;
  for (const Outcome& e : events)
    if (e.kind == DecodeEvent::Kind::packet) p.push_back(e.raw);
  return p;
}

// Decodes one complete input that must hold exactly one event.
DecodeEvent decode_one(Decoder& dec, const Bytes& wire) {
  dec.reset();
  dec.feed(wire);
  DecodeEvent e = dec.next();
  return e;
}

// ---- CRC ---------------------------------------------------------------------------------------

TEST(DynamixelCrc, MatchesEveryManualPacket) {
  for (const Example& ex : examples()) {
    const Bytes wire = hex(ex.wire);
    const std::uint16_t crc = crc16(wire.data(), wire.size() - 2);
    EXPECT_EQ(crc & 0xFF, wire[wire.size() - 2]) << ex.name;
    EXPECT_EQ(crc >> 8, wire[wire.size() - 1]) << ex.name;
    EXPECT_EQ(crc, crc_bitwise(wire.data(), wire.size() - 2)) << ex.name;
  }
}

TEST(DynamixelCrc, CatalogueCheckValue) {
  const std::string s = "123456789";  // CRC-16/BUYPASS check value
  const auto* p = reinterpret_cast<const std::uint8_t*>(s.data());
  EXPECT_EQ(crc16(p, s.size()), 0xFEE8);
  EXPECT_EQ(crc_bitwise(p, s.size()), 0xFEE8);
  EXPECT_EQ(crc16(p, 0), 0);
}

TEST(DynamixelCrc, TableAgreesWithBitwiseReferenceAndContinues) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 500; ++trial) {
    Bytes data(std::uniform_int_distribution<std::size_t>(0, 300)(rng));
    for (auto& b : data) b = static_cast<std::uint8_t>(rng());
    const std::uint16_t whole = crc16(data.data(), data.size());
    ASSERT_EQ(whole, crc_bitwise(data.data(), data.size()));
    const std::size_t cut = data.empty() ? 0 : rng() % data.size();
    EXPECT_EQ(crc16(data.data() + cut, data.size() - cut, crc16(data.data(), cut)), whole);
  }
}

// ---- Encoding and decoding the manual's packets ------------------------------------------------

TEST(DynamixelPacket, EncodesEveryManualPacketFromItsFields) {
  Bytes out;
  for (const Example& ex : examples()) {
    const Bytes params = hex(ex.params);
    Packet p{ex.id, ex.instruction, ex.error, params};
    EXPECT_EQ(copy(encode(p, out)), hex(ex.wire)) << ex.name;
  }
}

TEST(DynamixelPacket, DecodesEveryManualPacketExactly) {
  Decoder dec;
  for (const Example& ex : examples()) {
    const Bytes wire = hex(ex.wire);
    const DecodeEvent e = decode_one(dec, wire);
    ASSERT_EQ(e.kind, DecodeEvent::Kind::packet) << ex.name << ": " << to_string(e.error);
    EXPECT_EQ(e.packet.id, ex.id) << ex.name;
    EXPECT_EQ(e.packet.instruction, ex.instruction) << ex.name;
    EXPECT_EQ(e.packet.error, ex.error) << ex.name;
    EXPECT_EQ(copy(e.packet.params), hex(ex.params)) << ex.name;
    EXPECT_EQ(copy(e.raw), wire) << ex.name;
    EXPECT_EQ(e.skipped, 0u) << ex.name;
    EXPECT_FALSE(dec.next()) << ex.name;
  }
}

TEST(DynamixelInstructions, BuildersReproduceTheManualPackets) {
  Bytes out;
  EXPECT_EQ(copy(encode_ping(1, out)), hex("FF FF FD 00 01 03 00 01 19 4E"));
  EXPECT_EQ(copy(encode_ping(kBroadcastId, out)), hex("FF FF FD 00 FE 03 00 01 31 42"));
  EXPECT_EQ(copy(encode_ping_reply(1, 1030, 38, out)), hex("FF FF FD 00 01 07 00 55 00 06 04 26 65 5D"));
  EXPECT_EQ(copy(encode_ping_reply(2, 1030, 38, out)), hex("FF FF FD 00 02 07 00 55 00 06 04 26 6F 6D"));
  EXPECT_EQ(copy(encode_read(1, 132, 4, out)), hex("FF FF FD 00 01 07 00 02 84 00 04 00 1D 15"));
  std::uint8_t value[4];
  store_le<std::int32_t>(value, 166);
  EXPECT_EQ(copy(encode_status(1, 0, value, out)), hex("FF FF FD 00 01 08 00 55 00 A6 00 00 00 8C C0"));
  store_le<std::int32_t>(value, 512);
  EXPECT_EQ(copy(encode_write(1, 116, value, out)), hex("FF FF FD 00 01 09 00 03 74 00 00 02 00 00 CA 89"));
  EXPECT_EQ(copy(encode_status(1, 0, {}, out)), hex("FF FF FD 00 01 04 00 55 00 A1 0C"));
  EXPECT_EQ(copy(encode_sync_read(132, 4, {1, 2}, out)), hex("FF FF FD 00 FE 09 00 82 84 00 04 00 01 02 CE FA"));
  store_le<std::int32_t>(value, 2079);
  EXPECT_EQ(copy(encode_status(2, 0, value, out)), hex("FF FF FD 00 02 08 00 55 00 1F 08 00 00 BA BE"));
  std::uint8_t goals[8];
  store_le<std::int32_t>(goals, 150);
  store_le<std::int32_t>(goals + 4, 170);
  EXPECT_EQ(copy(encode_sync_write(116, 4, {1, 2}, goals, out)),
            hex("FF FF FD 00 FE 11 00 83 74 00 04 00 01 96 00 00 00 02 AA 00 00 00 82 87"));
  const BulkReadItem items[] = {{1, 144, 2}, {2, 146, 1}};
  EXPECT_EQ(copy(encode_bulk_read(items, out)), hex("FF FF FD 00 FE 0D 00 92 01 90 00 02 00 02 92 00 01 00 1A 05"));
  EXPECT_EQ(copy(encode_status(1, 0, {0x77, 0x00}, out)), hex("FF FF FD 00 01 06 00 55 00 77 00 C3 69"));
  EXPECT_EQ(copy(encode_status(2, 0, {0x24}, out)), hex("FF FF FD 00 02 05 00 55 00 24 8B A9"));
  // Bulk Write has no builder; PacketWriter composes it.
  PacketWriter w(out, kBroadcastId, Instruction::bulk_write);
  w.u8(1).u16(32).u16(2).u16(160).u8(2).u16(31).u16(1).u8(80);
  EXPECT_EQ(copy(w.finish()), hex("FF FF FD 00 FE 10 00 93 01 20 00 02 00 A0 00 02 1F 00 01 00 50 B7 68"));
}

TEST(DynamixelInstructions, ParsersReadTheManualPackets) {
  Decoder dec;
  // The packet's views point into the decoder: use each before decoding the next.
  auto packet = [&](const char* wire) {
    DecodeEvent e = decode_one(dec, hex(wire));
    EXPECT_EQ(e.kind, DecodeEvent::Kind::packet) << wire;
    return e.packet;
  };
  const auto ping = parse_ping_reply(packet("FF FF FD 00 01 07 00 55 00 06 04 26 65 5D"));
  ASSERT_TRUE(ping);
  EXPECT_EQ(ping->id, 1);
  EXPECT_EQ(ping->model_number, 1030);  // XM430-W210 in the manual's example
  EXPECT_EQ(ping->firmware, 38);

  const auto read = parse_read(packet("FF FF FD 00 01 07 00 02 84 00 04 00 1D 15"));
  ASSERT_TRUE(read);
  EXPECT_EQ(read->address, 132);
  EXPECT_EQ(read->length, 4);

  const Packet reply = packet("FF FF FD 00 01 08 00 55 00 A6 00 00 00 8C C0");
  EXPECT_TRUE(reply.status_error().ok());
  const auto data = parse_read_reply(reply, 4);
  ASSERT_TRUE(data);
  EXPECT_EQ(load_le<std::int32_t>(data->data()), 166);
  EXPECT_FALSE(parse_read_reply(reply, 2));
  EXPECT_FALSE(parse_ping_reply(reply));

  const auto reply2 = parse_read_reply(packet("FF FF FD 00 02 08 00 55 00 1F 08 00 00 BA BE"), 4);
  ASSERT_TRUE(reply2);
  EXPECT_EQ(load_le<std::int32_t>(reply2->data()), 2079);

  const auto write = parse_write(packet("FF FF FD 00 01 09 00 03 74 00 00 02 00 00 CA 89"));
  ASSERT_TRUE(write);
  EXPECT_EQ(write->address, 116);
  ASSERT_EQ(write->data.size(), 4u);
  EXPECT_EQ(load_le<std::int32_t>(write->data.data()), 512);

  const auto sread = parse_sync_read(packet("FF FF FD 00 FE 09 00 82 84 00 04 00 01 02 CE FA"));
  ASSERT_TRUE(sread);
  EXPECT_EQ(sread->address, 132);
  EXPECT_EQ(sread->length, 4);
  EXPECT_EQ(copy(sread->ids), (Bytes{1, 2}));

  const auto swrite =
      parse_sync_write(packet("FF FF FD 00 FE 11 00 83 74 00 04 00 01 96 00 00 00 02 AA 00 00 00 82 87"));
  ASSERT_TRUE(swrite);
  EXPECT_EQ(swrite->address, 116);
  EXPECT_EQ(swrite->length, 4);
  ASSERT_EQ(swrite->count(), 2u);
  EXPECT_EQ(swrite->id(0), 1);
  EXPECT_EQ(load_le<std::int32_t>(swrite->data(0).data()), 150);
  EXPECT_EQ(swrite->id(1), 2);
  EXPECT_EQ(load_le<std::int32_t>(swrite->data(1).data()), 170);

  const auto bread = parse_bulk_read(packet("FF FF FD 00 FE 0D 00 92 01 90 00 02 00 02 92 00 01 00 1A 05"));
  ASSERT_TRUE(bread);
  ASSERT_EQ(bread->count(), 2u);
  EXPECT_EQ(bread->item(0).id, 1);
  EXPECT_EQ(bread->item(0).address, 144);  // Present Input Voltage
  EXPECT_EQ(bread->item(0).length, 2);
  EXPECT_EQ(bread->item(1).id, 2);
  EXPECT_EQ(bread->item(1).address, 146);  // Present Temperature
  EXPECT_EQ(bread->item(1).length, 1);
  const auto voltage = parse_read_reply(packet("FF FF FD 00 01 06 00 55 00 77 00 C3 69"), 2);
  ASSERT_TRUE(voltage);
  EXPECT_EQ(load_le<std::uint16_t>(voltage->data()), 119);
  const auto temperature = parse_read_reply(packet("FF FF FD 00 02 05 00 55 00 24 8B A9"), 1);
  ASSERT_TRUE(temperature);
  EXPECT_EQ((*temperature)[0], 36);

  // Wrong instruction or parameter count.
  EXPECT_FALSE(parse_read(packet("FF FF FD 00 01 09 00 03 74 00 00 02 00 00 CA 89")));
  EXPECT_FALSE(parse_sync_write(packet("FF FF FD 00 FE 09 00 82 84 00 04 00 01 02 CE FA")));
  Bytes out;
  PacketWriter(out, 1, Instruction::write).u8(0x74).finish();  // address cut in half
  DecodeEvent e = decode_one(dec, out);
  ASSERT_EQ(e.kind, DecodeEvent::Kind::packet);
  EXPECT_FALSE(parse_write(e.packet));
  EXPECT_FALSE(parse_bulk_read(e.packet));
}

TEST(DynamixelInstructions, RejectInconsistentArguments) {
  Bytes out;
  EXPECT_THROW(encode_ping(0xFD, out), std::invalid_argument);
  EXPECT_THROW(encode_ping(0xFF, out), std::invalid_argument);
  EXPECT_THROW(encode_sync_read(132, 4, {1, 0xFE}, out), std::invalid_argument);
  EXPECT_THROW(encode_sync_write(116, 4, {1, 2}, {1, 2, 3, 4}, out), std::invalid_argument);
  EXPECT_THROW(encode_bulk_read({BulkReadItem{0xFF, 0, 1}}, out), std::invalid_argument);
  const Bytes huge(70000, 0);
  EXPECT_THROW(encode_write(1, 0, huge, out), std::length_error);
  EXPECT_THROW(Decoder(3), std::invalid_argument);
  EXPECT_THROW(Decoder(70000), std::invalid_argument);
}

TEST(DynamixelInstructions, ReusedBufferDoesNotReallocate) {
  Bytes out;
  out.reserve(256);
  const std::uint8_t* before = out.data();
  std::uint8_t currents[16] = {};
  for (int cycle = 0; cycle < 100; ++cycle) {
    encode_sync_read(xseries::kPresentCurrentVelocityPosition.address, xseries::kPresentCurrentVelocityPosition.size,
                     {1, 2, 3, 4, 5, 6, 7, 8}, out);
    encode_sync_write(xseries::kGoalCurrent.address, xseries::kGoalCurrent.size, {1, 2, 3, 4, 5, 6, 7, 8}, currents,
                      out);
  }
  EXPECT_EQ(out.data(), before);
}

// ---- Byte stuffing -----------------------------------------------------------------------------

// True when every FF FF FD in the stuffed region is followed by the stuffing FD.
bool region_is_stuffed(const Bytes& wire) {
  const std::size_t region_end = wire.size() - 2;
  int ff = 0;
  for (std::size_t i = 7; i < region_end; ++i) {
    if (wire[i] == 0xFD && ff == 2) {
      if (i + 1 >= region_end || wire[i + 1] != 0xFD) return false;
      ++i;
      ff = 0;
    } else {
      ff = wire[i] == 0xFF ? std::min(ff + 1, 2) : 0;
    }
  }
  return true;
}

TEST(DynamixelStuffing, InsertsFdAfterEachHeaderPattern) {
  Bytes out;
  // Write to address 0xFFFF the bytes FD FF FF FD: the pattern spans address and data, then
  // appears again at the end of the parameters (just before the CRC).
  encode_write(1, 0xFFFF, {0xFD, 0xFF, 0xFF, 0xFD}, out);
  const Bytes region(out.begin() + 7, out.end() - 2);
  EXPECT_EQ(region, hex("03 FF FF FD FD FF FF FD FD"));
  EXPECT_EQ(load_le<std::uint16_t>(out.data() + 5), out.size() - 7);  // Length after stuffing
  const std::uint16_t crc = crc_bitwise(out.data(), out.size() - 2);  // CRC after stuffing
  EXPECT_EQ(load_le<std::uint16_t>(out.data() + out.size() - 2), crc);

  // A status whose error byte starts the pattern; FF FF FF FD; an already stuffed-looking run.
  encode_status(7, 0xFF, {0xFF, 0xFD, 0x00}, out);
  EXPECT_EQ(Bytes(out.begin() + 7, out.end() - 2), hex("55 FF FF FD FD 00"));
  encode_write(1, 0x00FF, {0xFF, 0xFF, 0xFD}, out);
  EXPECT_EQ(Bytes(out.begin() + 7, out.end() - 2), hex("03 FF 00 FF FF FD FD"));
  encode_write(1, 0xFFFF, {0xFF, 0xFD, 0xFD}, out);
  EXPECT_EQ(Bytes(out.begin() + 7, out.end() - 2), hex("03 FF FF FF FD FD FD"));
  encode_write(1, 0xFFFF, {0xFD, 0xFF, 0xFF, 0xFD, 0xFD, 0xFF, 0xFF, 0xFD}, out);
  EXPECT_EQ(Bytes(out.begin() + 7, out.end() - 2), hex("03 FF FF FD FD FF FF FD FD FD FF FF FD FD"));
}

TEST(DynamixelStuffing, RoundTripsPayloadsFullOfPatterns) {
  std::mt19937 rng(11);
  const std::uint8_t alphabet[] = {0xFF, 0xFF, 0xFD, 0x00, 0x55};
  Bytes out;
  Decoder dec(0xFFFF);
  for (int trial = 0; trial < 2000; ++trial) {
    Bytes params(rng() % 40);
    for (auto& b : params) b = alphabet[rng() % 5];
    const bool status = rng() % 2;
    Packet p{static_cast<std::uint8_t>(rng() % 253), status ? Instruction::status : Instruction::write,
             status ? alphabet[rng() % 5] : std::uint8_t{0}, params};
    encode(p, out);
    const Bytes wire = out;
    ASSERT_TRUE(region_is_stuffed(wire));
    ASSERT_LE(wire.size(), max_encoded_size(params.size() + (status ? 2 : 1)));
    const DecodeEvent e = decode_one(dec, wire);
    // A header inside the region would be reported as truncated: stuffing must prevent it.
    ASSERT_EQ(e.kind, DecodeEvent::Kind::packet) << to_string(e.error);
    EXPECT_EQ(e.packet.id, p.id);
    EXPECT_EQ(e.packet.instruction, p.instruction);
    EXPECT_EQ(e.packet.error, p.error);
    EXPECT_EQ(copy(e.packet.params), params);
    EXPECT_EQ(copy(e.raw), wire);
  }
}

// ---- Streaming and resynchronization -----------------------------------------------------------

// The manual's packets with garbage between them: random bytes free of FF, lone FF runs, and
// header prefixes that never complete.
Bytes noisy_stream(std::mt19937& rng, std::vector<Bytes>& expected) {
  const std::vector<Bytes> junk = {hex("FF"),          hex("FF FF"),   hex("FF FF FD"), hex("FF FF FF FD 01"),
                                   hex("FF FF FD FD"), hex("00 FD 00")};
  Bytes stream;
  for (int round = 0; round < 3; ++round) {
    for (const Example& ex : examples()) {
      const int n = static_cast<int>(rng() % 12);
      for (int i = 0; i < n; ++i) stream.push_back(static_cast<std::uint8_t>(rng() % 0xFF));
      if (rng() % 2) {
        const Bytes& j = junk[rng() % junk.size()];
        stream.insert(stream.end(), j.begin(), j.end());
      }
      const Bytes wire = hex(ex.wire);
      stream.insert(stream.end(), wire.begin(), wire.end());
      expected.push_back(wire);
    }
  }
  return stream;
}

TEST(DynamixelDecoder, ResynchronizesWhateverTheChunking) {
  std::mt19937 rng(3);
  std::vector<Bytes> expected;
  const Bytes stream = noisy_stream(rng, expected);

  const auto whole = decode_all(stream);
  EXPECT_EQ(packets_of(whole), expected);
  for (const Outcome& o : whole) EXPECT_EQ(o.kind, DecodeEvent::Kind::packet);
  const auto bytewise = decode_all(stream, nullptr, 1);
  const auto random = decode_all(stream, &rng);
  ASSERT_EQ(bytewise.size(), whole.size());
  ASSERT_EQ(random.size(), whole.size());
  std::size_t skipped = 0;
  for (std::size_t i = 0; i < whole.size(); ++i) {
    EXPECT_EQ(bytewise[i].raw, whole[i].raw);
    EXPECT_EQ(bytewise[i].skipped, whole[i].skipped);
    EXPECT_EQ(random[i].raw, whole[i].raw);
    EXPECT_EQ(random[i].skipped, whole[i].skipped);
    skipped += whole[i].skipped + whole[i].raw.size();
  }
  EXPECT_EQ(skipped, stream.size());  // every byte is either part of a packet or skipped
}

TEST(DynamixelDecoder, CutOffPacketIsTruncatedAndTheNextOneSurvives) {
  const Bytes sync_write = hex("FF FF FD 00 FE 11 00 83 74 00 04 00 01 96 00 00 00 02 AA 00 00 00 82 87");
  const Bytes status = hex("FF FF FD 00 01 08 00 55 00 A6 00 00 00 8C C0");
  for (std::size_t cut = 1; cut < sync_write.size(); ++cut) {
    Bytes stream(sync_write.begin(), sync_write.begin() + static_cast<std::ptrdiff_t>(cut));
    stream.insert(stream.end(), status.begin(), status.end());
    for (std::size_t chunk : {std::size_t{0}, std::size_t{1}}) {
      const auto events = decode_all(stream, nullptr, chunk);
      ASSERT_EQ(packets_of(events), std::vector<Bytes>{status}) << "cut " << cut;
      if (cut >= 4) {  // a whole header arrived: the cut-off packet is reported
        ASSERT_GE(events.size(), 2u);
        EXPECT_EQ(events[0].kind, DecodeEvent::Kind::error);
        // Cut within ID or Length, the next header's FF bytes make them invalid.
        const DecodeError expected = cut == 4  ? DecodeError::bad_id
                                     : cut < 7 ? DecodeError::bad_length
                                               : DecodeError::truncated;
        EXPECT_EQ(events[0].error, expected) << "cut " << cut;
        if (cut >= 7)  // the rejected bytes are exactly the cut-off packet
          EXPECT_EQ(events[0].raw, Bytes(sync_write.begin(), sync_write.begin() + static_cast<std::ptrdiff_t>(cut)));
      }
    }
  }
  // The status was not held back until the cut-off packet's Length of bytes arrived.
  Decoder dec;
  dec.feed(sync_write.data(), 12);
  EXPECT_FALSE(dec.next());
  dec.feed(status);
  DecodeEvent e = dec.next();
  EXPECT_EQ(e.kind, DecodeEvent::Kind::error);
  EXPECT_EQ(e.error, DecodeError::truncated);
  e = dec.next();
  ASSERT_EQ(e.kind, DecodeEvent::Kind::packet);
  EXPECT_EQ(copy(e.raw), status);
}

TEST(DynamixelDecoder, PartialPacketAtEndOfInputIsTruncatedOnFlush) {
  const Bytes read = hex("FF FF FD 00 01 07 00 02 84 00 04 00 1D 15");
  Decoder dec;
  dec.feed(read.data(), 10);
  EXPECT_FALSE(dec.next());
  dec.flush();
  DecodeEvent e = dec.next();
  ASSERT_EQ(e.kind, DecodeEvent::Kind::error);
  EXPECT_EQ(e.error, DecodeError::truncated);
  EXPECT_EQ(copy(e.raw), Bytes(read.begin(), read.begin() + 10));
  EXPECT_FALSE(dec.next());
  EXPECT_EQ(dec.buffered(), 0u);
  dec.feed(read);  // usable again after the flush
  e = dec.next();
  ASSERT_EQ(e.kind, DecodeEvent::Kind::packet);
  EXPECT_EQ(e.packet.instruction, Instruction::read);
}

// ---- Typed errors ------------------------------------------------------------------------------

// A frame with a correct CRC over whatever bytes are given (header included in `head`).
Bytes with_crc(Bytes head) {
  const std::uint16_t crc = crc16(head.data(), head.size());
  head.push_back(static_cast<std::uint8_t>(crc));
  head.push_back(static_cast<std::uint8_t>(crc >> 8));
  return head;
}

TEST(DynamixelDecoder, CorruptedBytesGiveBadCrc) {
  const Bytes good = hex("FF FF FD 00 01 08 00 55 00 A6 00 00 00 8C C0");
  Decoder dec;
  for (std::size_t i = 7; i < good.size(); ++i) {
    Bytes bad = good;
    bad[i] ^= 0x10;
    bad.insert(bad.end(), good.begin(), good.end());
    dec.reset();
    dec.feed(bad);
    DecodeEvent e = dec.next();
    ASSERT_EQ(e.kind, DecodeEvent::Kind::error) << i;
    EXPECT_EQ(e.error, DecodeError::bad_crc) << i;
    e = dec.next();
    ASSERT_EQ(e.kind, DecodeEvent::Kind::packet) << i;  // the next packet is still found
    EXPECT_EQ(copy(e.raw), good);
    EXPECT_EQ(e.skipped, good.size() - 1);  // the rest of the corrupted frame
  }
}

TEST(DynamixelDecoder, LengthOutOfRangeIsRejectedWithoutWaiting) {
  Decoder dec;                                                   // max Length 1024
  DecodeEvent e = decode_one(dec, hex("FF FF FD 00 01 01 04"));  // Length 1025
  ASSERT_EQ(e.kind, DecodeEvent::Kind::error);
  EXPECT_EQ(e.error, DecodeError::bad_length);
  EXPECT_EQ(e.raw.size(), 7u);
  e = decode_one(dec, hex("FF FF FD 00 01 FF FF"));
  EXPECT_EQ(e.error, DecodeError::bad_length);
  e = decode_one(dec, hex("FF FF FD 00 01 02 00 01 00 00"));  // Length 2 < 3
  EXPECT_EQ(e.error, DecodeError::bad_length);
  // A status packet without its error byte, CRC correct.
  e = decode_one(dec, with_crc(hex("FF FF FD 00 01 03 00 55")));
  ASSERT_EQ(e.kind, DecodeEvent::Kind::error);
  EXPECT_EQ(e.error, DecodeError::bad_length);
  Decoder small(16);
  e = decode_one(small, hex("FF FF FD 00 01 11 00"));
  EXPECT_EQ(e.error, DecodeError::bad_length);
}

TEST(DynamixelDecoder, OtherTypedErrors) {
  Decoder dec;
  DecodeEvent e = decode_one(dec, hex("FF FF FD 00 FF 03 00 01 00 00"));
  ASSERT_EQ(e.kind, DecodeEvent::Kind::error);
  EXPECT_EQ(e.error, DecodeError::bad_id);
  e = decode_one(dec, hex("FF FF FD 00 FD 03 00 01 00 00"));
  EXPECT_EQ(e.error, DecodeError::bad_id);

  // Instruction 0x07 is not defined; the frame is well formed, so it is consumed whole.
  const Bytes unknown = with_crc(hex("FF FF FD 00 01 04 00 07 01"));
  const Bytes ping = hex("FF FF FD 00 01 03 00 01 19 4E");
  Bytes both = unknown;
  both.insert(both.end(), ping.begin(), ping.end());
  dec.reset();
  dec.feed(both);
  e = dec.next();
  ASSERT_EQ(e.kind, DecodeEvent::Kind::error);
  EXPECT_EQ(e.error, DecodeError::unknown_instruction);
  EXPECT_EQ(e.packet.id, 1);
  EXPECT_EQ(static_cast<int>(e.packet.instruction), 0x07);
  EXPECT_EQ(copy(e.raw), unknown);
  e = dec.next();
  ASSERT_EQ(e.kind, DecodeEvent::Kind::packet);
  EXPECT_EQ(e.skipped, 0u);

  // FF FF FD inside the region without its stuffing byte (at the end, or followed by another).
  e = decode_one(dec, with_crc(hex("FF FF FD 00 01 08 00 03 74 00 FF FF FD")));
  ASSERT_EQ(e.kind, DecodeEvent::Kind::error);
  EXPECT_EQ(e.error, DecodeError::bad_stuffing);
  e = decode_one(dec, with_crc(hex("FF FF FD 00 01 08 00 03 FF FF FD 01 00")));
  EXPECT_EQ(e.error, DecodeError::bad_stuffing);
  for (DecodeError err : {DecodeError::bad_id, DecodeError::bad_length, DecodeError::bad_crc, DecodeError::truncated,
                          DecodeError::bad_stuffing, DecodeError::unknown_instruction})
    EXPECT_STRNE(to_string(err), "unknown decode error");
}

TEST(DynamixelDecoder, StatusErrorByte) {
  Decoder dec;
  Bytes out;
  struct Case {
    std::uint8_t raw;
    bool alert;
    ErrorNumber number;
  };
  for (const Case& c :
       {Case{0x00, false, ErrorNumber::none}, Case{0x01, false, ErrorNumber::result_fail},
        Case{0x02, false, ErrorNumber::instruction_error}, Case{0x03, false, ErrorNumber::crc_error},
        Case{0x04, false, ErrorNumber::data_range_error}, Case{0x05, false, ErrorNumber::data_length_error},
        Case{0x06, false, ErrorNumber::data_limit_error}, Case{0x07, false, ErrorNumber::access_error},
        Case{0x80, true, ErrorNumber::none}, Case{0x84, true, ErrorNumber::data_range_error}}) {
    encode_status(3, c.raw, {}, out);
    const DecodeEvent e = decode_one(dec, out);
    ASSERT_EQ(e.kind, DecodeEvent::Kind::packet);
    const StatusError s = e.packet.status_error();
    EXPECT_EQ(s.alert(), c.alert) << int(c.raw);
    EXPECT_EQ(s.number(), c.number) << int(c.raw);
    EXPECT_EQ(s.ok(), c.number == ErrorNumber::none) << int(c.raw);
  }
  EXPECT_STREQ(to_string(ErrorNumber::access_error), "access error");
  EXPECT_STREQ(to_string(Instruction::sync_read), "sync read");
}

// ---- Little endian and the control table -------------------------------------------------------

TEST(DynamixelEndian, SignedAndUnsignedValues) {
  std::uint8_t b[4];
  store_le<std::int16_t>(b, -100);
  EXPECT_EQ(b[0], 0x9C);
  EXPECT_EQ(b[1], 0xFF);
  EXPECT_EQ(load_le<std::int16_t>(b), -100);
  EXPECT_EQ(load_le<std::uint16_t>(b), 0xFF9C);
  EXPECT_EQ(load_le_signed(b, 2), -100);
  EXPECT_EQ(load_le_unsigned(b, 2), 0xFF9Cu);
  store_le<std::int32_t>(b, -123456);
  EXPECT_EQ(load_le<std::int32_t>(b), -123456);
  EXPECT_EQ(load_le_signed(b, 4), -123456);
  EXPECT_EQ(load_le_signed(b, 1), static_cast<std::int8_t>(b[0]));
  EXPECT_EQ(load_le_unsigned(b, 3), 0u);
}

TEST(DynamixelControlTable, AddressesAndModelsOfTheEmanual) {
  using namespace xseries;
  EXPECT_EQ(kModelNumber.address, 0);
  EXPECT_EQ(kModelNumber.size, 2);
  EXPECT_EQ(kBaudRate.address, 8);
  EXPECT_EQ(kReturnDelayTime.address, 9);
  EXPECT_EQ(kOperatingMode.address, 11);
  EXPECT_EQ(kCurrentLimit.address, 38);
  EXPECT_EQ(kVelocityLimit.address, 44);
  EXPECT_EQ(kMaxPositionLimit.address, 48);
  EXPECT_EQ(kMinPositionLimit.address, 52);
  EXPECT_EQ(kTorqueEnable.address, 64);
  EXPECT_EQ(kHardwareErrorStatus.address, 70);
  EXPECT_EQ(kGoalCurrent.address, 102);
  EXPECT_EQ(kPresentCurrent.address, 126);
  EXPECT_EQ(kPresentVelocity.address, 128);
  EXPECT_EQ(kPresentPosition.address, 132);
  EXPECT_EQ(static_cast<int>(OperatingMode::current), 0);
  EXPECT_EQ(kXm430W350.number, 1020);
  EXPECT_EQ(kXm540W270.number, 1120);
  EXPECT_EQ(find_model(1120), &kXm540W270);
  EXPECT_EQ(find_model(1030), nullptr);
  EXPECT_EQ(baud_rate_bps(1), 57'600u);
  EXPECT_EQ(baud_rate_bps(3), 1'000'000u);
  EXPECT_EQ(baud_rate_bps(8), 0u);
}

TEST(DynamixelControlTable, UnitConversions) {
  using namespace xseries;
  constexpr double kPi = 3.14159265358979323846;
  EXPECT_DOUBLE_EQ(position_to_rad(2048), 0.0);
  EXPECT_DOUBLE_EQ(position_to_rad(3072), kPi / 2);
  EXPECT_DOUBLE_EQ(position_to_rad(0), -kPi);
  EXPECT_EQ(rad_to_position(0.0), 2048);
  EXPECT_EQ(rad_to_position(-kPi / 2), 1024);
  EXPECT_EQ(rad_to_position(position_to_rad(1234)), 1234);
  EXPECT_EQ(rad_to_position(std::nan("")), 2048);
  EXPECT_NEAR(velocity_to_rad_s(1), 0.229 * 2 * kPi / 60, 1e-15);
  EXPECT_NEAR(current_to_amps(100), 0.269, 1e-12);
  EXPECT_NEAR(current_to_amps(-1193), -3.20917, 1e-9);
  EXPECT_EQ(amps_to_current(0.269), 100);
  EXPECT_EQ(amps_to_current(-0.269), -100);
  EXPECT_EQ(amps_to_current(10.0, kXm430W350.max_current_limit), 1193);
  EXPECT_EQ(amps_to_current(-10.0, kXm430W350.max_current_limit), -1193);
  EXPECT_EQ(amps_to_current(1e9), 32767);
  EXPECT_EQ(amps_to_current(std::nan("")), 0);
}

}  // namespace
}  // namespace symoro::dynamixel
