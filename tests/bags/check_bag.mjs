#!/usr/bin/env node
// Test-only self-check of write_bag.mjs: reads an MCAP file (or a bag folder
// written by write_bag.mjs) back with @mcap/core's readers and prints one JSON
// line per message on stdout, in file order:
//   {"topic", "log_time_ns", "sequence", "stamp_sec", "stamp_nanosec", "frame_id",
//    "name", "position", "velocity", "effort"}          (sensor_msgs/msg/JointState)
//   {"topic", "log_time_ns", "sequence", "data"}        (std_msgs/msg/String)
// Doubles are printed so that they read back bit-exactly ("nan", "inf", "-inf", -0.0).
// A summary of the file (records, chunks, schemas, channels, ...) goes to stderr.
//
// Usage: node tests/bags/check_bag.mjs <file.mcap | bag folder>
// Exits non-zero when the file does not read back consistently.

import fs from "node:fs";
import path from "node:path";

import lz4 from "@foxglove/wasm-lz4";
import zstd from "@foxglove/wasm-zstd";
import { parse as parseMessageDefinition } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import lz4napi from "lz4-napi";

await lz4.isLoaded;
await zstd.isLoaded;

const decompressHandlers = {
  lz4: (buffer, size) => {
    const out = lz4(buffer, Number(size));
    // Cross-check with the writer's LZ4 library.
    if (Buffer.compare(out, lz4napi.decompressFrameSync(Buffer.from(buffer))) !== 0) {
      throw new Error("wasm-lz4 and lz4-napi disagree on a chunk");
    }
    return out;
  },
  zstd: (buffer, size) => zstd.decompress(buffer, Number(size)),
};

const LZ4_FRAME_MAGIC = "04224d18";
const ZSTD_FRAME_MAGIC = "28b52ffd";

function formatDouble(x) {
  if (Number.isNaN(x)) return '"nan"';
  if (x === Infinity) return '"inf"';
  if (x === -Infinity) return '"-inf"';
  if (Object.is(x, -0)) return "-0.0"; // "-0" reads back as the integer 0 in many JSON parsers
  return JSON.stringify(x); // shortest representation that reads back as the same double
}

function formatDoubles(a) {
  return "[" + Array.from(a, formatDouble).join(",") + "]";
}

function messageLine(topic, schemaName, record, value) {
  const head = `{"topic":${JSON.stringify(topic)},"log_time_ns":"${record.logTime}","sequence":${record.sequence}`;
  if (schemaName === "sensor_msgs/msg/JointState") {
    return (
      head +
      `,"stamp_sec":${value.header.stamp.sec},"stamp_nanosec":${value.header.stamp.nanosec}` +
      `,"frame_id":${JSON.stringify(value.header.frame_id)},"name":${JSON.stringify(value.name)}` +
      `,"position":${formatDoubles(value.position)},"velocity":${formatDoubles(value.velocity)}` +
      `,"effort":${formatDoubles(value.effort)}}`
    );
  }
  if (schemaName === "std_msgs/msg/String") {
    return head + `,"data":${JSON.stringify(value.data)}}`;
  }
  throw new Error(`no output format for ${schemaName}`);
}

function check(condition, message) {
  if (!condition) {
    throw new Error(message);
  }
}

/** Reads one MCAP file; returns its JSON lines and a summary. */
async function checkFile(file) {
  const bytes = fs.readFileSync(file);
  const summary = { file, records: {}, chunks: [], schemas: [], channels: [], metadata: [] };
  const schemas = new Map();
  const channels = new Map();
  const readers = new Map();
  const lines = [];
  const streamMessages = [];

  // 1. Stream reader, every record in file order (chunks decompressed).
  const stream = new McapStreamReader({ includeChunks: true, decompressHandlers, validateCrcs: true });
  stream.append(bytes);
  for (let record; (record = stream.nextRecord()); ) {
    summary.records[record.type] = (summary.records[record.type] ?? 0) + 1;
    switch (record.type) {
      case "Header":
        summary.header = { profile: record.profile, library: record.library };
        break;
      case "Schema":
        if (!schemas.has(record.id)) {
          const text = new TextDecoder().decode(record.data);
          schemas.set(record.id, { ...record, text });
          summary.schemas.push({ id: record.id, name: record.name, encoding: record.encoding, bytes: record.data.byteLength });
        }
        break;
      case "Channel":
        if (!channels.has(record.id)) {
          channels.set(record.id, record);
          summary.channels.push({
            id: record.id, topic: record.topic, schemaId: record.schemaId,
            messageEncoding: record.messageEncoding, metadata: Object.fromEntries(record.metadata),
          });
        }
        break;
      case "Chunk": {
        const magic = Buffer.from(record.records.subarray(0, 4)).toString("hex");
        if (record.compression === "lz4") check(magic === LZ4_FRAME_MAGIC, `lz4 chunk starts with ${magic}`);
        if (record.compression === "zstd") check(magic === ZSTD_FRAME_MAGIC, `zstd chunk starts with ${magic}`);
        summary.chunks.push({
          compression: record.compression, compressed: record.records.byteLength,
          uncompressed: Number(record.uncompressedSize), magic,
          start: String(record.messageStartTime), end: String(record.messageEndTime),
        });
        break;
      }
      case "Metadata":
        summary.metadata.push({ name: record.name, metadata: Object.fromEntries(record.metadata) });
        break;
      case "Statistics":
        summary.statistics = {
          messageCount: String(record.messageCount), schemaCount: record.schemaCount,
          channelCount: record.channelCount, chunkCount: record.chunkCount,
          messageStartTime: String(record.messageStartTime), messageEndTime: String(record.messageEndTime),
        };
        break;
      case "Footer":
        summary.footer = { summaryStart: String(record.summaryStart), summaryOffsetStart: String(record.summaryOffsetStart) };
        break;
      case "Message": {
        const channel = channels.get(record.channelId);
        check(channel, `message on unknown channel ${record.channelId}`);
        check(channel.messageEncoding === "cdr", `channel ${channel.topic}: encoding ${channel.messageEncoding}`);
        const schema = schemas.get(channel.schemaId);
        check(schema && schema.encoding === "ros2msg", `channel ${channel.topic}: no ros2msg schema`);
        check(record.publishTime === record.logTime, "publish_time != log_time");
        if (!readers.has(schema.id)) {
          readers.set(schema.id, new MessageReader(parseMessageDefinition(schema.text, { ros2: true })));
        }
        const reader = readers.get(schema.id);
        const value = reader.readMessage(record.data);
        check(!reader.lastReadHadTrailingBytes(), `${channel.topic}: trailing bytes after the message`);
        lines.push(messageLine(channel.topic, schema.name, record, value));
        streamMessages.push(record);
        break;
      }
      default:
        break;
    }
  }
  check(stream.done(), `${file}: the stream reader did not reach the end magic`);
  summary.messages = streamMessages.length;
  if (summary.statistics) {
    check(summary.statistics.messageCount === String(streamMessages.length), "statistics message count differs");
    check(summary.statistics.chunkCount === summary.chunks.length, "statistics chunk count differs");
  }

  // 2. Indexed reader, when the file has a summary: it must find the same messages
  //    (in log-time order) through the chunk indexes and message indexes.
  if (summary.footer && summary.footer.summaryStart !== "0") {
    const indexed = await McapIndexedReader.Initialize({
      readable: {
        size: async () => BigInt(bytes.byteLength),
        read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
      },
      decompressHandlers,
    });
    summary.indexed = {
      chunkIndexes: indexed.chunkIndexes.length,
      channels: indexed.channelsById.size,
      schemas: indexed.schemasById.size,
      metadataIndexes: indexed.metadataIndexes.length,
    };
    check(indexed.chunkIndexes.length === summary.chunks.length, "chunk index count differs from chunk count");
    if (indexed.chunkIndexes.length > 0) {
      const key = (m) => `${m.channelId}/${m.sequence}/${m.logTime}/${Buffer.from(m.data).toString("hex")}`;
      const expected = streamMessages.map(key).sort();
      const got = [];
      let last = -1n;
      for await (const m of indexed.readMessages()) {
        check(m.logTime >= last, "indexed reader: messages not in log-time order");
        last = m.logTime;
        got.push(key(m));
      }
      got.sort();
      check(JSON.stringify(got) === JSON.stringify(expected), "indexed reader: messages differ from the stream reader's");
      summary.indexed.messages = got.length;
    }
  }
  return { lines, summary };
}

function yamlNumbers(text, key) {
  return [...text.matchAll(new RegExp(`^\\s*(?:- )?${key}: (\\d+)$`, "gm"))].map((m) => BigInt(m[1]));
}

async function main(argv) {
  if (argv.length !== 1) {
    process.stderr.write("usage: node check_bag.mjs <file.mcap | bag folder>\n");
    return 2;
  }
  const target = argv[0];
  if (!fs.statSync(target).isDirectory()) {
    const { lines, summary } = await checkFile(target);
    process.stdout.write(lines.map((l) => l + "\n").join(""));
    process.stderr.write(JSON.stringify(summary) + "\n");
    return 0;
  }

  // A bag folder: the files listed in metadata.yaml, in order; counts and times cross-checked.
  const yaml = fs.readFileSync(path.join(target, "metadata.yaml"), "utf8");
  const paths = [...yaml.matchAll(/^ {4}- path: (.+)$/gm)].map((m) => m[1]);
  const rel = yaml.split("relative_file_paths:")[1].split("files:")[0];
  check(JSON.stringify([...rel.matchAll(/^ {4}- (.+)$/gm)].map((m) => m[1])) === JSON.stringify(paths),
    "relative_file_paths and files[].path differ");
  const starts = yamlNumbers(yaml, "nanoseconds_since_epoch");
  const durations = yamlNumbers(yaml, "nanoseconds");
  const counts = yamlNumbers(yaml, "message_count");
  // Order in the file: bag message_count, one per topic, then one per file.
  const fileCounts = counts.slice(counts.length - paths.length);
  let total = 0;
  let minTime = null;
  let maxTime = null;
  for (const [k, p] of paths.entries()) {
    const { lines, summary } = await checkFile(path.join(target, p));
    process.stdout.write(lines.map((l) => l + "\n").join(""));
    process.stderr.write(JSON.stringify(summary) + "\n");
    check(BigInt(summary.messages) === fileCounts[k], `${p}: ${summary.messages} messages, metadata.yaml says ${fileCounts[k]}`);
    const times = lines.map((l) => BigInt(JSON.parse(l).log_time_ns));
    if (times.length > 0) {
      const lo = times.reduce((a, b) => (b < a ? b : a));
      const hi = times.reduce((a, b) => (b > a ? b : a));
      check(starts[k + 1] === lo && durations[k + 1] === hi - lo, `${p}: starting_time/duration differ from metadata.yaml`);
      minTime = minTime === null || lo < minTime ? lo : minTime;
      maxTime = maxTime === null || hi > maxTime ? hi : maxTime;
    }
    total += summary.messages;
  }
  check(BigInt(total) === counts[0], `bag: ${total} messages, metadata.yaml says ${counts[0]}`);
  if (minTime !== null) {
    check(starts[0] === minTime && durations[0] === maxTime - minTime, "bag starting_time/duration differ from metadata.yaml");
  }
  return 0;
}

main(process.argv.slice(2)).then(
  (code) => {
    process.exitCode = code; // not process.exit(): let piped stdout drain
  },
  (err) => {
    process.stderr.write(`check_bag.mjs: ${err.stack ?? err}\n`);
    process.exitCode = 1;
  },
);
