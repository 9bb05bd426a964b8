#!/usr/bin/env node
// Test-only: round-trips write_bag.mjs through check_bag.mjs for every
// compression (none, lz4, zstd), chunked and unchunked, one and two topics,
// and a bag folder of two files; doubles are compared bit for bit.
// Usage: node tests/bags/selftest.mjs   (prints "N passed, N failed")

import { execFileSync } from "node:child_process";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { fileURLToPath } from "node:url";

const here = path.dirname(fileURLToPath(import.meta.url));
const tmp = fs.mkdtempSync(path.join(os.tmpdir(), "write_bag_selftest-"));

// Deterministic doubles, including -0, subnormals and extremes.
let state = 12345n;
function nextBits() {
  state = (state * 6364136223846793005n + 1442695040888963407n) & ((1n << 64n) - 1n);
  return state;
}
function double() {
  const view = new DataView(new ArrayBuffer(8));
  const pick = Number(nextBits() % 10n);
  if (pick === 0) return -0;
  if (pick === 1) return 5e-324;
  view.setBigUint64(0, nextBits() & ~(0x7ffn << 52n) | (BigInt(pick * 150) << 52n)); // finite
  return view.getFloat64(0);
}
const g17 = (x) => (Object.is(x, -0) ? "-0" : x.toPrecision(17)); // like C++ "%.17g"

function messages(n, twoTopics) {
  const out = [];
  for (let i = 0; i < n; i++) {
    const t = 1700000000001000000n + BigInt(i) * 2000000n;
    out.push({
      topic: "/joint_states", publisher: i % 2, log_time_ns: String(t),
      stamp_sec: Number(t / 1000000000n), stamp_nanosec: Number(t % 1000000000n), frame_id: "",
      name: ["joint1", "joint2", "Gelenk_\u00e4"],
      position: [double(), double(), double()],
      velocity: i % 3 === 0 ? [] : [double(), double(), double()],
      effort: [double(), double(), double()],
    });
    if (twoTopics && i % 4 === 0) {
      out.push({ topic: "/rosout_like", type: "std_msgs/msg/String", log_time_ns: String(t + 1n), data: `hello ${i} \u00fc` });
    }
  }
  return out;
}

// JSON with every array double written with 17 significant digits.
function specText(spec) {
  return JSON.stringify(spec, (key, value) =>
    ["position", "velocity", "effort"].includes(key) ? value.map((x) => `@${g17(x)}@`) : value,
  ).replace(/"@([^@]*)@"/g, "$1");
}

function bits(x) {
  const v = new DataView(new ArrayBuffer(8));
  v.setFloat64(0, x);
  return v.getBigUint64(0);
}
function readDouble(x) {
  return typeof x === "number" ? x : { nan: NaN, inf: Infinity, "-inf": -Infinity }[x];
}

function compare(expected, stdout) {
  const got = stdout.trim() === "" ? [] : stdout.trim().split("\n").map((l) => JSON.parse(l));
  if (got.length !== expected.length) throw new Error(`${got.length} messages read, ${expected.length} written`);
  expected.forEach((e, i) => {
    const g = got[i];
    const where = `message ${i}`;
    if (g.topic !== e.topic || g.log_time_ns !== e.log_time_ns) throw new Error(`${where}: topic or time differs`);
    if (e.type === "std_msgs/msg/String") {
      if (g.data !== e.data) throw new Error(`${where}: data differs`);
      return;
    }
    for (const k of ["stamp_sec", "stamp_nanosec", "frame_id", "name"]) {
      if (JSON.stringify(g[k]) !== JSON.stringify(e[k])) throw new Error(`${where}: ${k} differs`);
    }
    for (const k of ["position", "velocity", "effort"]) {
      const a = e[k].map(bits).join();
      const b = g[k].map((x) => bits(readDouble(x))).join();
      if (a !== b) throw new Error(`${where}: ${k} differs bitwise`);
    }
  });
}

const cases = [];
for (const compression of ["none", "lz4", "zstd"]) {
  for (const chunked of [true, false]) {
    if (!chunked && compression !== "none") continue;
    for (const two of [false, true]) {
      cases.push({ name: `${compression}_${chunked ? "chunked" : "unchunked"}_${two ? "two" : "one"}_topics`, compression, chunked, two });
    }
  }
}
cases.push({ name: "bag_folder_lz4", compression: "lz4", chunked: true, two: true, folder: true });
cases.push({ name: "bag_folder_unchunked", compression: "none", chunked: false, two: true, folder: true });

let passed = 0;
let failed = 0;
for (const c of cases) {
  const msgs = messages(c.folder ? 50 : 300, c.two);
  const target = path.join(tmp, c.folder ? c.name : `${c.name}.mcap`);
  const spec = {
    compression: c.compression, chunked: c.chunked, chunk_size: 4096, profile: "ros2", messages: msgs,
    ...(c.folder ? { bag_folder: { dir: target, files: [0, 30] } } : { out: target, bag_folder: null }),
  };
  const specFile = path.join(tmp, `${c.name}.json`);
  fs.writeFileSync(specFile, specText(spec));
  try {
    execFileSync(process.execPath, [path.join(here, "write_bag.mjs"), specFile], { stdio: ["ignore", "ignore", "pipe"] });
    const out = execFileSync(process.execPath, [path.join(here, "check_bag.mjs"), target], {
      encoding: "utf8", stdio: ["ignore", "pipe", "pipe"], maxBuffer: 64 << 20,
    });
    compare(msgs, out);
    console.log(`ok   ${c.name}`);
    passed++;
  } catch (err) {
    console.log(`FAIL ${c.name}: ${err.stderr ? String(err.stderr).trim() : err.message}`);
    failed++;
  }
}
fs.rmSync(tmp, { recursive: true, force: true });
console.log(`${passed} passed, ${failed} failed`);
process.exitCode = failed === 0 ? 0 : 1;
