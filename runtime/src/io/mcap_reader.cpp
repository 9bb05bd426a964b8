// MCAP, read as a stream from its start (symoro/io/mcap.hpp; https://mcap.dev/spec). Only the
// records a reader of messages needs are decoded (header, schema, channel, message, chunk,
// data end, footer); every other opcode, known or not, is skipped by its length, as the
// specification asks of readers.
#include "symoro/io/mcap.hpp"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <vector>

#include <boost/crc.hpp>
#include <fmt/format.h>
#include <lz4frame.h>
#include <zstd.h>

#include "symoro/error.hpp"

namespace symoro::io::mcap {

namespace {

constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};
enum Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kDataEnd = 0x0F,
};
// A chunk larger than this decompressed is refused rather than allocated (rosbag2 writes 768 KiB
// chunks by default; a corrupt size field must not take the machine's memory).
constexpr std::uint64_t kLargestChunk = std::uint64_t{1} << 31;

// Little-endian fields of one record's content, every read bounded by it.
class Fields {
 public:
  Fields(const std::uint8_t* p, std::size_t size, std::uint64_t offset, const std::string& source)
      : p_(p), size_(size), offset_(offset), source_(source) {}

  template <typename T>
  T integer(const char* what) {
    need(sizeof(T), what);
    T v = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i) v |= static_cast<T>(static_cast<T>(p_[at_ + i]) << (8 * i));
    at_ += sizeof(T);
    return v;
  }
  std::string string(const char* what) {
    const std::uint32_t n = integer<std::uint32_t>(what);
    need(n, what);
    std::string s(reinterpret_cast<const char*>(p_ + at_), n);
    at_ += n;
    return s;
  }
  std::map<std::string, std::string> string_map(const char* what) {
    const std::uint32_t n = integer<std::uint32_t>(what);
    need(n, what);
    Fields inner(p_ + at_, n, offset_ + at_, source_);
    at_ += n;
    std::map<std::string, std::string> m;
    while (inner.left() > 0) {
      std::string key = inner.string(what);
      m[key] = inner.string(what);
    }
    return m;
  }
  // `n` bytes from here (a byte array's content).
  const std::uint8_t* bytes(std::uint64_t n, const char* what) {
    need(n, what);
    const std::uint8_t* b = p_ + at_;
    at_ += static_cast<std::size_t>(n);
    return b;
  }
  std::size_t left() const { return size_ - at_; }
  std::uint64_t offset() const { return offset_ + at_; }

 private:
  void need(std::uint64_t n, const char* what) const {
    if (n > size_ - at_)
      throw DataError(source_, 0,
                      fmt::format("byte {}: the {} needs {} bytes, the record has {} left (a corrupt file)",
                                  offset_ + at_, what, n, size_ - at_));
  }
  const std::uint8_t* p_;
  std::size_t size_, at_ = 0;
  std::uint64_t offset_;
  const std::string& source_;
};

// Decompresses a chunk's records. The output grows as the decoder produces it (never to more
// than the chunk declares): a size field that lies costs no memory the data does not back.
std::vector<std::uint8_t> decompress(const std::string& compression, const std::uint8_t* in, std::size_t size,
                                     std::uint64_t uncompressed, std::uint64_t offset, const std::string& source) {
  const auto fail = [&](const std::string& why) {
    return DataError(source, 0, fmt::format("byte {}: a chunk compressed with {} {}", offset, compression, why));
  };
  if (compression != "lz4" && compression != "zstd")
    throw fail("is not readable: this reader knows lz4, zstd and uncompressed chunks");
  if (uncompressed > kLargestChunk)
    throw fail(
        fmt::format("declares {} bytes decompressed, more than this reader takes ({})", uncompressed, kLargestChunk));
  const auto want = static_cast<std::size_t>(uncompressed);
  std::vector<std::uint8_t> out(std::min<std::size_t>(want, 4 * size + 65536));
  std::size_t done = 0, used = 0;
  bool finished = false;
  // One decoder step into out[done..]: how much it wrote and read, and whether its frame ended.
  const auto grow = [&] {
    if (out.size() < want && out.size() - done < 65536) out.resize(std::min(want, 2 * out.size()));
  };
  if (compression == "zstd") {
    ZSTD_DCtx* ctx = ZSTD_createDCtx();
    if (!ctx) throw fail("needs a context zstd refused");
    while (!finished) {
      grow();
      ZSTD_outBuffer o{out.data(), out.size(), done};
      ZSTD_inBuffer i{in, size, used};
      const std::size_t r = ZSTD_decompressStream(ctx, &o, &i);
      if (ZSTD_isError(r)) {
        ZSTD_freeDCtx(ctx);
        throw fail(std::string("does not decompress: ") + ZSTD_getErrorName(r));
      }
      const bool progress = o.pos != done || i.pos != used;
      done = o.pos, used = i.pos;
      finished = r == 0;
      if (!progress && (done == out.size() ? out.size() == want : used == size)) break;
    }
    ZSTD_freeDCtx(ctx);
  } else {
    LZ4F_dctx* ctx = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) throw fail("needs a context lz4 refused");
    while (!finished) {
      grow();
      std::size_t dst = out.size() - done, src = size - used;
      const std::size_t r = LZ4F_decompress(ctx, out.data() + done, &dst, in + used, &src, nullptr);
      if (LZ4F_isError(r)) {
        LZ4F_freeDecompressionContext(ctx);
        throw fail(std::string("does not decompress: ") + LZ4F_getErrorName(r));
      }
      done += dst;
      used += src;
      finished = r == 0;
      if (dst == 0 && src == 0 && (done == out.size() ? out.size() == want : used == size)) break;
    }
    LZ4F_freeDecompressionContext(ctx);
  }
  if (!finished || done != want)
    throw fail(
        fmt::format("gives {} bytes{}, not the {} it declares", done, finished ? "" : " (frame unfinished)", want));
  out.resize(done);
  return out;
}

class Reader {
 public:
  Reader(const std::string& source, const MessageHandler& on_message) : source_(source), on_message_(on_message) {}

  // The records of `bytes` from `at` (a file's data, or a chunk's records when `in_chunk`); returns
  // where the first record that is not whole starts (size when all are), and whether the footer
  // was met.
  std::size_t records(const std::uint8_t* bytes, std::size_t size, std::size_t at, std::uint64_t base, bool in_chunk,
                      bool& footer) {
    while (at < size) {
      if (size - at < 9) return at;
      Fields head(bytes + at, 9, base + at, source_);
      const auto op = head.integer<std::uint8_t>("opcode");
      const auto length = head.integer<std::uint64_t>("record length");
      if (length > size - at - 9) {
        if (in_chunk)
          throw DataError(source_, 0,
                          fmt::format("byte {}: a record in a chunk claims {} bytes, the chunk has {} left", base + at,
                                      length, size - at - 9));
        return at;
      }
      Fields f(bytes + at + 9, static_cast<std::size_t>(length), base + at + 9, source_);
      record(op, f, in_chunk);
      at += 9 + static_cast<std::size_t>(length);
      if (op == kFooter && !in_chunk) {
        footer = true;
        return at;
      }
    }
    return at;
  }

  ReadSummary summary;

 private:
  void record(std::uint8_t op, Fields& f, bool in_chunk) {
    if (in_chunk && op != kSchema && op != kChannel && op != kMessage)
      throw DataError(source_, 0,
                      fmt::format("byte {}: opcode {:#04x} inside a chunk (chunks hold schemas, channels and "
                                  "messages)",
                                  f.offset() - 9, op));
    switch (op) {
      case kHeader:
        summary.profile = f.string("header's profile");
        summary.library = f.string("header's library");
        break;
      case kSchema: {
        Schema s;
        s.id = f.integer<std::uint16_t>("schema id");
        s.name = f.string("schema name");
        s.encoding = f.string("schema encoding");
        const auto n = f.integer<std::uint32_t>("schema data length");
        const std::uint8_t* d = f.bytes(n, "schema data");
        s.data.assign(reinterpret_cast<const char*>(d), n);
        if (s.id == 0) throw DataError(source_, 0, fmt::format("byte {}: schema id 0 is reserved", f.offset()));
        schemas_[s.id] = std::move(s);
        break;
      }
      case kChannel: {
        Channel c;
        c.id = f.integer<std::uint16_t>("channel id");
        c.schema_id = f.integer<std::uint16_t>("channel's schema id");
        c.topic = f.string("channel topic");
        c.message_encoding = f.string("channel message encoding");
        c.metadata = f.string_map("channel metadata");
        channels_[c.id] = std::move(c);
        break;
      }
      case kMessage:
        message(f);
        break;
      case kChunk:
        chunk(f);
        break;
      default:
        break;  // footer, indexes, statistics, attachments, metadata, data end: not needed
    }
  }

  void message(Fields& f) {
    const std::uint64_t at = f.offset() - 9;
    Message m;
    m.channel_id = f.integer<std::uint16_t>("message's channel id");
    m.sequence = f.integer<std::uint32_t>("message sequence");
    m.log_time = f.integer<std::uint64_t>("message log time");
    m.publish_time = f.integer<std::uint64_t>("message publish time");
    m.size = f.left();
    m.data = f.bytes(m.size, "message data");
    const auto c = channels_.find(m.channel_id);
    if (c == channels_.end())
      throw DataError(
          source_, 0,
          fmt::format("byte {}: a message on channel {}, which no channel record before it defines", at, m.channel_id));
    const Schema* schema = nullptr;
    if (c->second.schema_id != 0) {
      const auto s = schemas_.find(c->second.schema_id);
      if (s == schemas_.end())
        throw DataError(source_, 0,
                        fmt::format("byte {}: channel {} ({}) names schema {}, which no schema record defines", at,
                                    c->second.id, c->second.topic, c->second.schema_id));
      schema = &s->second;
    }
    ++summary.messages;
    on_message_(m, c->second, schema);
  }

  void chunk(Fields& f) {
    const std::uint64_t at = f.offset() - 9;
    f.integer<std::uint64_t>("chunk start time");
    f.integer<std::uint64_t>("chunk end time");
    const auto uncompressed = f.integer<std::uint64_t>("chunk's uncompressed size");
    const auto crc = f.integer<std::uint32_t>("chunk's uncompressed CRC");
    const std::string compression = f.string("chunk compression");
    const auto n = f.integer<std::uint64_t>("chunk records length");
    const std::uint8_t* records_at = f.bytes(n, "chunk records");
    std::vector<std::uint8_t> plain;
    const std::uint8_t* data = records_at;
    std::size_t size = static_cast<std::size_t>(n);
    if (!compression.empty()) {
      plain = decompress(compression, records_at, size, uncompressed, at, source_);
      data = plain.data();
      size = plain.size();
    } else if (uncompressed != n) {
      throw DataError(source_, 0,
                      fmt::format("byte {}: an uncompressed chunk of {} bytes declares {}", at, n, uncompressed));
    }
    if (crc != 0) {  // 0: not computed
      boost::crc_32_type sum;
      sum.process_bytes(data, size);
      if (sum.checksum() != crc)
        throw DataError(source_, 0,
                        fmt::format("byte {}: the chunk's CRC-32 is {:#010x}, its records give {:#010x} (a corrupt "
                                    "file)",
                                    at, crc, sum.checksum()));
    }
    bool footer = false;
    records(data, size, 0, 0, true, footer);
    ++summary.chunks;
  }

  const std::string& source_;
  const MessageHandler& on_message_;
  std::map<std::uint16_t, Schema> schemas_;
  std::map<std::uint16_t, Channel> channels_;
};

}  // namespace

ReadSummary read_mcap(const std::uint8_t* bytes, std::size_t size, const std::string& source,
                      const MessageHandler& on_message) {
  if (size < sizeof kMagic || std::memcmp(bytes, kMagic, sizeof kMagic) != 0)
    throw DataError(source, 0, "not an MCAP file (its first 8 bytes are not MCAP's magic)");
  Reader reader(source, on_message);
  bool footer = false;
  const std::size_t end = reader.records(bytes, size, sizeof kMagic, 0, false, footer);
  ReadSummary s = reader.summary;
  s.bytes = size;
  const bool closed = footer && size - end == sizeof kMagic && std::memcmp(bytes + end, kMagic, sizeof kMagic) == 0;
  if (!closed) {
    if (footer)
      throw DataError(
          source, 0,
          fmt::format("byte {}: {} bytes after the footer, where only the closing magic belongs", end, size - end));
    s.cut_short = true;
    s.cut_at = end;
  }
  return s;
}

ReadSummary read_mcap(const std::filesystem::path& file, const MessageHandler& on_message) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open " + file.string());
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return read_mcap(bytes.data(), bytes.size(), file.string(), on_message);
}

}  // namespace symoro::io::mcap
