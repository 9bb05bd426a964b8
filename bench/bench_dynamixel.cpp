// The DYNAMIXEL Protocol 2.0 work of one 1 kHz control cycle of the CRANE-X7 (8 servos), without
// the wire: encoding the Sync Write of goal currents and the Sync Read of present current,
// velocity and position, and decoding the 8 status replies (CRC and byte stuffing included).
// The wire itself takes far longer (about 0.3 ms for these bytes at 3 Mbps); these numbers show
// the protocol layer is a negligible share of the 1 ms budget.
#include <array>
#include <cstdint>
#include <vector>

#include <benchmark/benchmark.h>

#include "symoro/dynamixel/control_table.hpp"
#include "symoro/dynamixel/crc.hpp"
#include "symoro/dynamixel/decoder.hpp"
#include "symoro/dynamixel/instructions.hpp"

namespace {

using namespace symoro::dynamixel;

const std::array<std::uint8_t, 8> kIds{2, 3, 4, 5, 6, 7, 8, 9};

void BM_Crc16_100Bytes(benchmark::State& state) {
  std::vector<std::uint8_t> data(100);
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<std::uint8_t>(i * 37 + 11);
  for (auto _ : state) benchmark::DoNotOptimize(crc16(data.data(), data.size()));
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * 100);
}
BENCHMARK(BM_Crc16_100Bytes);

// Goal Current (102, 2 bytes) to 8 servos; the current pattern includes 0xFF bytes so that
// stuffing is checked on the way.
void BM_EncodeSyncWriteGoalCurrent8(benchmark::State& state) {
  Buffer out;
  std::array<std::uint8_t, 16> data{};
  for (std::size_t i = 0; i < data.size(); ++i) data[i] = i % 3 == 0 ? 0xFF : static_cast<std::uint8_t>(i);
  for (auto _ : state) {
    const ByteView v =
        encode_sync_write(102, 2, ByteView(kIds.data(), kIds.size()), ByteView(data.data(), data.size()), out);
    benchmark::DoNotOptimize(v);
  }
}
BENCHMARK(BM_EncodeSyncWriteGoalCurrent8);

void BM_EncodeSyncReadState8(benchmark::State& state) {
  Buffer out;
  for (auto _ : state) {
    const ByteView v = encode_sync_read(126, 10, ByteView(kIds.data(), kIds.size()), out);
    benchmark::DoNotOptimize(v);
  }
}
BENCHMARK(BM_EncodeSyncReadState8);

// The 8 status replies of the Sync Read (10 bytes each: current, velocity, position), fed as one
// stream, decoded and their data read.
void BM_DecodeStateReplies8(benchmark::State& state) {
  Buffer stream, one;
  for (std::uint8_t id : kIds) {
    std::array<std::uint8_t, 10> params{};
    for (std::size_t i = 0; i < params.size(); ++i) params[i] = static_cast<std::uint8_t>(id * 13 + i * 7);
    const ByteView v = encode_status(id, 0, ByteView(params.data(), params.size()), one);
    stream.insert(stream.end(), v.begin(), v.end());
  }
  Decoder decoder;
  for (auto _ : state) {
    decoder.feed(ByteView(stream.data(), stream.size()));
    int packets = 0;
    while (DecodeEvent e = decoder.next()) packets += e.kind == DecodeEvent::Kind::packet;
    if (packets != 8) state.SkipWithError("not 8 replies");
    benchmark::DoNotOptimize(packets);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * stream.size()));
}
BENCHMARK(BM_DecodeStateReplies8);

}  // namespace
