// A reader of MCAP files (the ROS 2 bag format since Iron), written against the published
// specification (https://mcap.dev/spec, format version 0): the magic, then records of an opcode
// (1 byte) and a length (uint64, little endian); schemas, channels and messages, inside chunks
// (compressed with lz4 frames or zstd, or not at all) or beside them. Read in one pass from the
// start, as a stream: the summary section is not needed, so a file cut short (a recorder that
// died) still gives the messages before the cut, and the reader says where it was cut.
//
// Errors: DataError(file, 0, "byte <offset>: ...") for what is broken rather than cut: a wrong
// magic, a record whose fields overrun it, an unknown compression, a chunk whose decompressed size
// or CRC-32 is not what it declares, a message on a channel never defined.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>

namespace symoro::io::mcap {

struct Schema {
  std::uint16_t id = 0;
  std::string name;      // e.g. "sensor_msgs/msg/JointState"
  std::string encoding;  // e.g. "ros2msg"
  std::string data;      // the definition's text for ros2msg
};

struct Channel {
  std::uint16_t id = 0, schema_id = 0;  // schema 0: none
  std::string topic, message_encoding;  // e.g. "/joint_states", "cdr"
  std::map<std::string, std::string> metadata;
};

struct Message {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0, publish_time = 0;  // ns (log_time: when the recorder received it)
  const std::uint8_t* data = nullptr;            // valid during the callback only
  std::size_t size = 0;
};

// What a pass over a file saw.
struct ReadSummary {
  std::string profile, library;  // the header's ("ros2" for rosbag2)
  std::uint64_t messages = 0;    // messages handed to the callback
  std::uint64_t chunks = 0;      // chunks read
  std::uint64_t bytes = 0;       // the file's size
  // The file ends without its footer and closing magic: cut short at `cut_at` bytes (the start
  // of the first record that was not whole); the messages before it were read.
  bool cut_short = false;
  std::uint64_t cut_at = 0;
};

// Called for each message, in file order, with its channel and schema (null for schema 0).
using MessageHandler = std::function<void(const Message&, const Channel&, const Schema*)>;

// Reads `file` from start to end. Throws DataError as above, std::runtime_error when the file
// cannot be opened.
ReadSummary read_mcap(const std::filesystem::path& file, const MessageHandler& on_message);

// The same over bytes in memory (`source` names them in errors; the fuzzer's entry).
ReadSummary read_mcap(const std::uint8_t* bytes, std::size_t size, const std::string& source,
                      const MessageHandler& on_message);

}  // namespace symoro::io::mcap
