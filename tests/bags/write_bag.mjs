#!/usr/bin/env node
// Test-only: writes ROS 2 bags (MCAP files, or a rosbag2 bag folder) with an
// MCAP writer independent of the project's C++ code, so that the project's own
// MCAP reader can be tested against files it did not write itself.
//
// Usage: node tests/bags/write_bag.mjs <spec.json>
// The spec format is described in README.md beside this file.

import fs from "node:fs";
import path from "node:path";

import { CdrWriter } from "@foxglove/cdr";
import { parse as parseMessageDefinition } from "@foxglove/rosmsg";
import { MessageWriter } from "@foxglove/rosmsg2-serialization";
import { McapWriter, VERSION as MCAP_CORE_VERSION } from "@mcap/core";

// ---------------------------------------------------------------------------
// Message definitions, registered the way rosbag2's MCAP storage plugin does:
// schema encoding "ros2msg", the root .msg text followed by each dependency
// after a line of 80 '=' and a line "MSG: <type as written in the field>".
// The fields are those of ROS 2 Humble/Iron; the comments are this file's own.

const TIME_MSG = `# builtin_interfaces/msg/Time (test copy): seconds and nanoseconds.

int32 sec

uint32 nanosec
`;

const HEADER_MSG = `# std_msgs/msg/Header (test copy): stamp and coordinate frame.

builtin_interfaces/Time stamp

string frame_id
`;

const JOINT_STATE_MSG = `# sensor_msgs/msg/JointState (test copy).
# The arrays have the same length, or are empty.

std_msgs/Header header

string[] name
float64[] position
float64[] velocity
float64[] effort
`;

const STRING_MSG = `# std_msgs/msg/String (test copy).

string data
`;

const SEPARATOR = "=".repeat(80) + "\n";

/** Appends a dependency the way rosbag2's message_definition_cache does. */
function dependency(name, text) {
  return "\n" + SEPARATOR + "MSG: " + name + "\n" + text;
}

const SCHEMA_TEXT = {
  "sensor_msgs/msg/JointState":
    JOINT_STATE_MSG +
    dependency("std_msgs/Header", HEADER_MSG + dependency("builtin_interfaces/Time", TIME_MSG)),
  "std_msgs/msg/String": STRING_MSG,
};

const DEFAULT_TYPE = "sensor_msgs/msg/JointState";
const DEFAULT_CHUNK_SIZE = 786432; // the MCAP C++ writer's default, which rosbag2 uses
const ZSTD_LEVEL = 3;

// ---------------------------------------------------------------------------
// @foxglove/cdr 3.5.0's CdrWriter.string() takes a string's UTF-16 length for
// its UTF-8 byte count, so a non-ASCII string is written truncated (fixed
// upstream in foxglove/cdr pull request 35, not yet released). When the
// installed version still has that fault, its string() is replaced by one that
// writes the UTF-8 bytes; MessageWriter's size estimate is only a first
// capacity, CdrWriter grows its buffer as needed.

function cdrStringIsUtf8() {
  const w = new CdrWriter({ size: 4 });
  w.string("\u00e4");
  return Buffer.from(w.data).equals(Buffer.from([0, 1, 0, 0, 3, 0, 0, 0, 0xc3, 0xa4, 0]));
}

if (!cdrStringIsUtf8()) {
  const encoder = new TextEncoder();
  CdrWriter.prototype.string = function string(value, writeLength = true) {
    const bytes = encoder.encode(value);
    if (writeLength) {
      this.uint32(bytes.length + 1); // with the NUL terminator
    }
    this.resizeIfNeeded(bytes.length + 1);
    this.array.set(bytes, this.offset);
    this.array[this.offset + bytes.length] = 0;
    this.offset += bytes.length + 1;
    return this;
  };
  if (!cdrStringIsUtf8()) {
    throw new Error("write_bag.mjs: could not make @foxglove/cdr write UTF-8 strings");
  }
}

// ---------------------------------------------------------------------------
// Spec validation

class SpecError extends Error {}

function fail(where, message) {
  throw new SpecError(`${where}: ${message}`);
}

function isObject(v) {
  return typeof v === "object" && v !== null && !Array.isArray(v);
}

function checkKeys(obj, allowed, where) {
  for (const key of Object.keys(obj)) {
    if (!allowed.includes(key)) {
      fail(where, `unknown key "${key}" (allowed: ${allowed.join(", ")})`);
    }
  }
}

const UINT64_MAX = (1n << 64n) - 1n;

function parseTimeNs(v, where) {
  if (typeof v === "string" && /^[0-9]+$/.test(v)) {
    const t = BigInt(v);
    if (t > UINT64_MAX) {
      fail(where, `${v} does not fit in uint64`);
    }
    return t;
  }
  if (typeof v === "number" && Number.isSafeInteger(v) && v >= 0) {
    return BigInt(v);
  }
  fail(where, `expected a decimal string of nanoseconds (uint64), got ${JSON.stringify(v)}`);
}

function parseInteger(v, min, max, where) {
  if (typeof v !== "number" || !Number.isInteger(v) || v < min || v > max) {
    fail(where, `expected an integer in [${min}, ${max}], got ${JSON.stringify(v)}`);
  }
  return v;
}

function parseString(v, where) {
  if (typeof v !== "string") {
    fail(where, `expected a string, got ${JSON.stringify(v)}`);
  }
  if (v.includes("\0")) {
    fail(where, "a CDR string cannot hold a NUL character");
  }
  return v;
}

const SPECIAL_DOUBLES = {
  nan: NaN,
  inf: Infinity,
  infinity: Infinity,
  "+inf": Infinity,
  "+infinity": Infinity,
  "-inf": -Infinity,
  "-infinity": -Infinity,
};

function parseDoubleArray(v, where) {
  if (!Array.isArray(v)) {
    fail(where, `expected an array of numbers, got ${JSON.stringify(v)}`);
  }
  const out = new Float64Array(v.length);
  v.forEach((x, i) => {
    if (typeof x === "number") {
      out[i] = x; // JSON.parse rounds correctly: 17 significant digits give the exact double
    } else if (typeof x === "string" && x.toLowerCase() in SPECIAL_DOUBLES) {
      out[i] = SPECIAL_DOUBLES[x.toLowerCase()];
    } else {
      fail(`${where}[${i}]`, `expected a number (or "nan", "inf", "-inf"), got ${JSON.stringify(x)}`);
    }
  });
  return out;
}

function parseStringArray(v, where) {
  if (!Array.isArray(v)) {
    fail(where, `expected an array of strings, got ${JSON.stringify(v)}`);
  }
  return v.map((s, i) => parseString(s, `${where}[${i}]`));
}

const TOPIC_RE = /^\/?[A-Za-z_~{][A-Za-z0-9_/{}~]*$/;

const MESSAGE_KEYS = {
  "sensor_msgs/msg/JointState": [
    "topic", "type", "publisher", "log_time_ns",
    "stamp_sec", "stamp_nanosec", "frame_id", "name", "position", "velocity", "effort",
  ],
  "std_msgs/msg/String": ["topic", "type", "publisher", "log_time_ns", "data"],
};

function parseMessage(m, index) {
  const where = `messages[${index}]`;
  if (!isObject(m)) {
    fail(where, "expected an object");
  }
  const type = m.type ?? DEFAULT_TYPE;
  if (!(type in MESSAGE_KEYS)) {
    fail(`${where}.type`, `unsupported type ${JSON.stringify(type)} (supported: ${Object.keys(MESSAGE_KEYS).join(", ")})`);
  }
  checkKeys(m, MESSAGE_KEYS[type], where);
  if (typeof m.topic !== "string" || !TOPIC_RE.test(m.topic)) {
    fail(`${where}.topic`, `expected a ROS topic name, got ${JSON.stringify(m.topic)}`);
  }
  if (m.log_time_ns === undefined) {
    fail(where, `"log_time_ns" is required`);
  }
  const logTime = parseTimeNs(m.log_time_ns, `${where}.log_time_ns`);
  if (m.publisher !== undefined) {
    parseInteger(m.publisher, 0, Number.MAX_SAFE_INTEGER, `${where}.publisher`);
  }
  let value;
  if (type === "sensor_msgs/msg/JointState") {
    value = {
      header: {
        stamp: {
          sec: parseInteger(m.stamp_sec ?? 0, -(2 ** 31), 2 ** 31 - 1, `${where}.stamp_sec`),
          nanosec: parseInteger(m.stamp_nanosec ?? 0, 0, 2 ** 32 - 1, `${where}.stamp_nanosec`),
        },
        frame_id: parseString(m.frame_id ?? "", `${where}.frame_id`),
      },
      name: parseStringArray(m.name ?? [], `${where}.name`),
      position: parseDoubleArray(m.position ?? [], `${where}.position`),
      velocity: parseDoubleArray(m.velocity ?? [], `${where}.velocity`),
      effort: parseDoubleArray(m.effort ?? [], `${where}.effort`),
    };
  } else {
    value = { data: parseString(m.data ?? "", `${where}.data`) };
  }
  return { topic: m.topic, type, logTime, value };
}

const SPEC_KEYS = [
  "out", "compression", "chunked", "chunk_size", "profile", "messages", "bag_folder",
  "sequence", "first_channel_id", "ros_distro",
];

function parseSpec(spec) {
  if (!isObject(spec)) {
    fail("spec", "expected a JSON object");
  }
  checkKeys(spec, SPEC_KEYS, "spec");

  const compression = spec.compression ?? "none";
  if (!["none", "lz4", "zstd"].includes(compression)) {
    fail("compression", `expected "none", "lz4" or "zstd", got ${JSON.stringify(compression)}`);
  }
  const chunked = spec.chunked ?? true;
  if (typeof chunked !== "boolean") {
    fail("chunked", `expected true or false, got ${JSON.stringify(chunked)}`);
  }
  if (!chunked && compression !== "none") {
    fail("compression", `"${compression}" needs "chunked": true (only chunks are compressed)`);
  }
  const chunkSize =
    spec.chunk_size == null
      ? DEFAULT_CHUNK_SIZE
      : parseInteger(spec.chunk_size, 1, 2 ** 31 - 1, "chunk_size");
  const profile = spec.profile == null ? "ros2" : parseString(spec.profile, "profile");
  const sequence = spec.sequence ?? "count";
  if (!["count", "zero"].includes(sequence)) {
    fail("sequence", `expected "count" or "zero", got ${JSON.stringify(sequence)}`);
  }
  const firstChannelId =
    spec.first_channel_id == null ? 1 : parseInteger(spec.first_channel_id, 0, 65000, "first_channel_id");
  const rosDistro =
    spec.ros_distro === undefined ? "humble" : spec.ros_distro === null ? null : parseString(spec.ros_distro, "ros_distro");

  if (!Array.isArray(spec.messages)) {
    fail("messages", "expected an array");
  }
  const messages = spec.messages.map(parseMessage);

  // One channel per topic, in order of first appearance; a topic keeps one type.
  const topics = new Map();
  for (const [i, m] of messages.entries()) {
    const known = topics.get(m.topic);
    if (known === undefined) {
      topics.set(m.topic, { type: m.type, firstIndex: i, count: 0 });
    } else if (known.type !== m.type) {
      fail(`messages[${i}].type`, `topic ${m.topic} already has type ${known.type}, not ${m.type}`);
    }
    topics.get(m.topic).count++;
  }

  let out = null;
  let bagFolder = null;
  if (spec.bag_folder != null) {
    const bf = spec.bag_folder;
    if (!isObject(bf)) {
      fail("bag_folder", "expected null or an object {dir, files}");
    }
    checkKeys(bf, ["dir", "files"], "bag_folder");
    if (typeof bf.dir !== "string" || bf.dir === "" || path.basename(path.resolve(bf.dir)) === "") {
      fail("bag_folder.dir", `expected a folder path, got ${JSON.stringify(bf.dir)}`);
    }
    const files = bf.files ?? [0];
    if (!Array.isArray(files) || files.length === 0 || files[0] !== 0) {
      fail("bag_folder.files", `expected an array of message indices starting with 0, got ${JSON.stringify(bf.files)}`);
    }
    files.forEach((start, k) => {
      parseInteger(start, 0, messages.length, `bag_folder.files[${k}]`);
      if (k > 0 && start <= files[k - 1]) {
        fail(`bag_folder.files[${k}]`, "the indices must increase strictly");
      }
    });
    bagFolder = { dir: path.resolve(bf.dir), files };
  } else {
    if (typeof spec.out !== "string" || spec.out === "") {
      fail("out", `expected an output file path, got ${JSON.stringify(spec.out)}`);
    }
    out = path.resolve(spec.out);
  }

  return {
    out, bagFolder, compression, chunked, chunkSize, profile, sequence, firstChannelId, rosDistro,
    messages, topics,
  };
}

// ---------------------------------------------------------------------------
// Writing

async function loadCompressor(compression) {
  if (compression === "lz4") {
    const lz4 = (await import("lz4-napi")).default;
    // LZ4 frame format (magic 04 22 4D 18), which is what MCAP's "lz4" means.
    return (data) => ({ compression: "lz4", compressedData: lz4.compressFrameSync(Buffer.from(data.buffer, data.byteOffset, data.byteLength)) });
  }
  if (compression === "zstd") {
    const zstd = (await import("@foxglove/wasm-zstd")).default;
    await zstd.isLoaded;
    return (data) => ({ compression: "zstd", compressedData: zstd.compress(data, ZSTD_LEVEL) });
  }
  return undefined;
}

/** IWritable over a file descriptor. */
class FileWritable {
  #fd;
  #position = 0n;
  constructor(fd) {
    this.#fd = fd;
  }
  async write(buffer) {
    let done = 0;
    while (done < buffer.byteLength) {
      done += fs.writeSync(this.#fd, buffer, done, buffer.byteLength - done);
    }
    this.#position += BigInt(buffer.byteLength);
  }
  position() {
    return this.#position;
  }
}

const serializers = new Map();
function serializer(type) {
  if (!serializers.has(type)) {
    serializers.set(type, new MessageWriter(parseMessageDefinition(SCHEMA_TEXT[type], { ros2: true })));
  }
  return serializers.get(type);
}

/**
 * Writes messages[begin, end) to one MCAP file. `topicNames` lists the topics
 * to register (in channel-id order); rosbag2 registers every topic it knows of
 * when it opens a file.
 */
async function writeMcap(file, spec, begin, end, topicNames, compressChunk) {
  const tmp = `${file}.tmp-${process.pid}`;
  const fd = fs.openSync(tmp, "w");
  try {
    const writer = new McapWriter({
      writable: new FileWritable(fd),
      useChunks: spec.chunked,
      useChunkIndex: spec.chunked,
      chunkSize: spec.chunkSize,
      compressChunk,
      startChannelId: spec.firstChannelId,
    });
    await writer.start({ profile: spec.profile, library: `write_bag.mjs (@mcap/core ${MCAP_CORE_VERSION})` });
    if (spec.rosDistro !== null) {
      // rosbag2's MCAP plugin writes this record when it opens a file.
      await writer.addMetadata({ name: "rosbag2", metadata: new Map([["ROS_DISTRO", spec.rosDistro]]) });
    }
    const schemaIds = new Map();
    const channelIds = new Map();
    for (const topic of topicNames) {
      const type = spec.topics.get(topic).type;
      if (!schemaIds.has(type)) {
        schemaIds.set(type, await writer.registerSchema({
          name: type,
          encoding: "ros2msg",
          data: new TextEncoder().encode(SCHEMA_TEXT[type]),
        }));
      }
      channelIds.set(topic, await writer.registerChannel({
        topic,
        schemaId: schemaIds.get(type),
        messageEncoding: "cdr",
        metadata: new Map([["offered_qos_profiles", ""]]),
      }));
    }
    const sequences = new Map();
    for (let i = begin; i < end; i++) {
      const m = spec.messages[i];
      const seq = spec.sequence === "zero" ? 0 : (sequences.get(m.topic) ?? 0) + 1;
      sequences.set(m.topic, seq);
      await writer.addMessage({
        channelId: channelIds.get(m.topic),
        sequence: seq,
        logTime: m.logTime,
        publishTime: m.logTime,
        data: serializer(m.type).writeMessage(m.value),
      });
    }
    await writer.end();
    fs.closeSync(fd);
    fs.renameSync(tmp, file);
  } catch (err) {
    try { fs.closeSync(fd); } catch { /* already closed */ }
    fs.rmSync(tmp, { force: true });
    throw err;
  }
}

function timeRange(messages, begin, end) {
  if (begin >= end) {
    return { start: 0n, duration: 0n };
  }
  let min = messages[begin].logTime;
  let max = min;
  for (let i = begin + 1; i < end; i++) {
    const t = messages[i].logTime;
    if (t < min) min = t;
    if (t > max) max = t;
  }
  return { start: min, duration: max - min };
}

function yamlString(s) {
  // Plain scalars where YAML reads them back as the same string, else double-quoted (JSON escapes are YAML escapes).
  if (/^[A-Za-z_/~][A-Za-z0-9_/.~{}-]*$/.test(s) && !/^(true|false|yes|no|on|off|null|y|n|~)$/i.test(s)) {
    return s;
  }
  return JSON.stringify(s);
}

/** metadata.yaml in rosbag2's format, version 5 (Humble). */
function metadataYaml(spec, fileNames) {
  const { files } = spec.bagFolder;
  const all = timeRange(spec.messages, 0, spec.messages.length);
  const lines = [
    "",
    "rosbag2_bagfile_information:",
    "  version: 5",
    "  storage_identifier: mcap",
    "  duration:",
    `    nanoseconds: ${all.duration}`,
    "  starting_time:",
    `    nanoseconds_since_epoch: ${all.start}`,
    `  message_count: ${spec.messages.length}`,
  ];
  if (spec.topics.size === 0) {
    lines.push("  topics_with_message_count: []");
  } else {
    lines.push("  topics_with_message_count:");
    for (const [name, t] of spec.topics) {
      lines.push(
        "    - topic_metadata:",
        `        name: ${yamlString(name)}`,
        `        type: ${t.type}`,
        "        serialization_format: cdr",
        '        offered_qos_profiles: ""',
        `      message_count: ${t.count}`,
      );
    }
  }
  lines.push('  compression_format: ""', '  compression_mode: ""', "  relative_file_paths:");
  for (const f of fileNames) {
    lines.push(`    - ${yamlString(f)}`);
  }
  lines.push("  files:");
  fileNames.forEach((f, k) => {
    const begin = files[k];
    const end = k + 1 < files.length ? files[k + 1] : spec.messages.length;
    const r = timeRange(spec.messages, begin, end);
    lines.push(
      `    - path: ${yamlString(f)}`,
      "      starting_time:",
      `        nanoseconds_since_epoch: ${r.start}`,
      "      duration:",
      `        nanoseconds: ${r.duration}`,
      `      message_count: ${end - begin}`,
    );
  });
  return lines.join("\n"); // like yaml-cpp: a leading empty line, no final newline
}

async function main(argv) {
  if (argv.length !== 1 || argv[0] === "-h" || argv[0] === "--help") {
    process.stderr.write("usage: node write_bag.mjs <spec.json>\n");
    return 2;
  }
  let raw;
  try {
    raw = JSON.parse(fs.readFileSync(argv[0], "utf8"));
  } catch (err) {
    process.stderr.write(`write_bag.mjs: cannot read spec ${argv[0]}: ${err.message}\n`);
    return 2;
  }
  let spec;
  try {
    spec = parseSpec(raw);
  } catch (err) {
    if (err instanceof SpecError) {
      process.stderr.write(`write_bag.mjs: bad spec ${argv[0]}: ${err.message}\n`);
      return 2;
    }
    throw err;
  }
  const compressChunk = await loadCompressor(spec.compression);
  const allTopics = [...spec.topics.keys()];

  if (spec.bagFolder === null) {
    fs.mkdirSync(path.dirname(spec.out), { recursive: true });
    await writeMcap(spec.out, spec, 0, spec.messages.length, allTopics, compressChunk);
    return 0;
  }

  const { dir, files } = spec.bagFolder;
  if (fs.existsSync(dir) && fs.readdirSync(dir).length > 0) {
    process.stderr.write(`write_bag.mjs: bag folder ${dir} exists and is not empty\n`);
    return 2;
  }
  fs.mkdirSync(dir, { recursive: true });
  const base = path.basename(dir);
  const fileNames = files.map((_, k) => `${base}_${k}.mcap`);
  for (let k = 0; k < files.length; k++) {
    const begin = files[k];
    const end = k + 1 < files.length ? files[k + 1] : spec.messages.length;
    // Topics known to the recorder by the end of this file, in channel order.
    const known = allTopics.filter((t) => spec.topics.get(t).firstIndex < end);
    await writeMcap(path.join(dir, fileNames[k]), spec, begin, end, known, compressChunk);
  }
  fs.writeFileSync(path.join(dir, "metadata.yaml"), metadataYaml(spec, fileNames));
  return 0;
}

main(process.argv.slice(2)).then(
  (code) => {
    process.exitCode = code; // not process.exit(): let piped stdout drain
  },
  (err) => {
    process.stderr.write(`write_bag.mjs: ${err.stack ?? err}\n`);
    process.exitCode = 1;
  },
);
