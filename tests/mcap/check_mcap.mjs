// The independent check of linesim's run.mcap: the MCAP reader of
// @mcap/core (Foxglove's TypeScript implementation, from npm) with fzstd's
// zstd decompressor reads the file two ways (streamed record by record, and
// through its summary and indexes), validates every CRC, and compares what
// it reads with the run's signals.csv. Chunks in lz4 are decompressed by
// lz4js, in zstd by fzstd.
//   node check_mcap.mjs RUN.mcap signals.csv expect.json
// expect.json (written by tests/mcap/mcap_test.cc from the loaded scenario):
//   {compression, beams: {UNIT: n}, angular_step: {UNIT: rad}, x, y, yaw: CSV
//    columns, carried: {ID: [x0, y0, belt travel column, direction rad, belt frame]},
//    entities: [static entity ids], scan_period_ns, signal_period_ns,
//    status: how the run ended (ok, failed, interrupted), stop_time_s}
// Exit 0 with "mcap check: ok ..." or 1 with the first failure.
import fs from "node:fs";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { crc32 } from "@foxglove/crc";
import { decompress } from "fzstd";
import lz4 from "lz4js";

const [mcapFile, csvFile, expectFile] = process.argv.slice(2);
const fail = (message) => {
  console.error(`mcap check: FAILED: ${message}`);
  process.exit(1);
};
const check = (ok, message) => {
  if (!ok) fail(message);
};

const bytes = new Uint8Array(fs.readFileSync(mcapFile));
const expect = JSON.parse(fs.readFileSync(expectFile, "utf8"));
const decompressHandlers = {
  zstd: (buffer, size) => decompress(buffer, new Uint8Array(Number(size))),
  lz4: (buffer, size) => lz4.decompress(buffer, Number(size)),
};

// 1. Streamed: every record in file order, chunk CRCs validated.
const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true, includeChunks: true });
stream.append(bytes);
const streamed = [];
const counts = {};
let dataEnd, footer;
let chunks = 0;
for (let r; (r = stream.nextRecord()); ) {
  counts[r.type] = (counts[r.type] ?? 0) + 1;
  if (r.type === "Message") streamed.push(r);
  if (r.type === "DataEnd") dataEnd = r;
  if (r.type === "Footer") footer = r;
  if (r.type === "Chunk") {
    chunks++;
    check(r.compression === expect.compression,
          `chunk compression '${r.compression}', expected ${expect.compression}`);
    check(r.uncompressedCrc !== 0, "a chunk without its CRC");
  }
}
check(stream.done(), "the stream reader did not reach the closing magic");
check(dataEnd !== undefined && footer !== undefined, "no data end or footer record");

// 2. Indexed: summary (its CRC validated), statistics, chunk indexes,
// message indexes.
const readable = {
  size: async () => BigInt(bytes.length),
  read: async (offset, length) => bytes.subarray(Number(offset), Number(offset + length)),
};
const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
check(footer.summaryCrc !== 0, "the footer carries no summary CRC");
check(dataEnd.dataSectionCrc !== 0, "the data end carries no data section CRC");
const dataCrc = crc32(bytes.subarray(0, Number(reader.dataEndOffset)));
check(dataCrc === dataEnd.dataSectionCrc,
      `data section CRC ${dataEnd.dataSectionCrc}, computed ${dataCrc}`);
const stats = reader.statistics;
check(stats !== undefined, "no statistics record in the summary");
for (const op of [3, 4, 8, 11]) {
  check(reader.summaryOffsetsByOpcode.has(op), `no summary offset for opcode ${op}`);
}
check(reader.chunkIndexes.length === chunks && stats.chunkCount === chunks,
      `${chunks} chunks, ${reader.chunkIndexes.length} chunk indexes, statistics ${stats.chunkCount}`);
check(Number(stats.messageCount) === streamed.length,
      `statistics count ${stats.messageCount} messages, the stream has ${streamed.length}`);
check(counts.MessageIndex >= chunks, "chunks without message indexes");
const indexed = [];
for await (const m of reader.readMessages({ validateCrcs: true })) indexed.push(m);
check(indexed.length === streamed.length,
      `indexed read gives ${indexed.length} messages, streamed ${streamed.length}`);
const key = (m) => `${m.channelId}/${m.sequence}`;
const byKey = new Map(streamed.map((m) => [key(m), m]));
let previous = -1n;
for (const m of indexed) {
  const s = byKey.get(key(m));
  check(s !== undefined && s.logTime === m.logTime &&
        Buffer.compare(Buffer.from(s.data), Buffer.from(m.data)) === 0,
        `message ${key(m)} differs between indexed and streamed reads`);
  check(m.logTime >= previous, "indexed read out of log-time order");
  previous = m.logTime;
}
for (const [id, n] of stats.channelMessageCounts) {
  const seen = streamed.filter((m) => m.channelId === id).length;
  check(Number(n) === seen, `channel ${id}: statistics ${n}, read ${seen}`);
}
check(stats.messageStartTime === indexed[0].logTime &&
      stats.messageEndTime === indexed[indexed.length - 1].logTime,
      "statistics' start and end times are not the messages'");

// 3. Content: JSON on Foxglove's schemas, compared with signals.csv.
const decoder = new TextDecoder();
const topicOf = (m) => reader.channelsById.get(m.channelId).topic;
const schemaOf = (m) => reader.schemasById.get(reader.channelsById.get(m.channelId).schemaId);
for (const c of reader.channelsById.values()) {
  check(c.messageEncoding === "json", `${c.topic}: message encoding ${c.messageEncoding}`);
  const s = reader.schemasById.get(c.schemaId);
  check(s.encoding === "jsonschema", `${c.topic}: schema encoding ${s.encoding}`);
  JSON.parse(decoder.decode(s.data));
}
const lines = fs.readFileSync(csvFile, "utf8").trim().split("\n");
const header = lines[0].split(",");
const column = Object.fromEntries(header.map((h, i) => [h, i]));
const rows = new Map();  // nanoseconds -> values
for (const line of lines.slice(1)) {
  const v = line.split(",").map(Number);
  rows.set(BigInt(Math.round(v[0] * 1e9)), v);
}
const nsOf = (t) => BigInt(t.sec) * 1000000000n + BigInt(t.nsec);
const same = (json, csv) => (json === null ? !Number.isFinite(csv) : json === csv);

let tf = 0, scans = 0, signals = 0, scenes = 0, statics = 0, mounts = 0, logs = 0;
const lastScan = {};
const carriedSeen = new Set();
for (const m of indexed) {
  const topic = topicOf(m);
  const msg = JSON.parse(decoder.decode(m.data));
  const row = rows.get(m.logTime);
  if (topic === "/tf") {
    check(schemaOf(m).name === "foxglove.FrameTransforms", "/tf schema");
    check(row !== undefined, `/tf at ${m.logTime} ns: no signals.csv row then`);
    const base = msg.transforms.find((t) => t.child_frame_id === "base_link");
    check(base.parent_frame_id === "map", "base_link's parent is not map");
    check(nsOf(base.timestamp) === m.logTime, "/tf timestamp is not its log time");
    check(base.translation.x === row[column[expect.x]] && base.translation.y === row[column[expect.y]],
          `/tf at ${m.logTime} ns: base_link at (${base.translation.x}, ${base.translation.y}), ` +
          `signals.csv (${row[column[expect.x]]}, ${row[column[expect.y]]})`);
    const q = base.rotation;
    const yaw = Math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z));
    // The chassis's yaw output comes from the same attitude: only rounding
    // apart (1e-9 rad is 1e6 times a double's resolution at pi).
    check(Math.abs(yaw - row[column[expect.yaw]]) < 1e-9,
          `/tf at ${m.logTime} ns: yaw ${yaw}, signals.csv ${row[column[expect.yaw]]}`);
    // Each belt's frame: moved by the belt's recorded travel along it.
    for (const c of Object.values(expect.carried)) {
      const belt = msg.transforms.find((t) => t.child_frame_id === c[4]);
      check(belt !== undefined && belt.parent_frame_id === "map", `/tf has no map -> ${c[4]}`);
      const d = row[column[c[2]]];
      check(Math.abs(belt.translation.x - d * Math.cos(c[3])) < 1e-12 &&
            Math.abs(belt.translation.y - d * Math.sin(c[3])) < 1e-12,
            `/tf at ${m.logTime} ns: ${c[4]} at (${belt.translation.x}, ${belt.translation.y}), ` +
            `travel ${d} m`);
    }
    tf++;
  } else if (topic === "/tf/mounts") {
    check(schemaOf(m).name === "foxglove.FrameTransforms", "/tf/mounts schema");
    for (const unit of Object.keys(expect.beams)) {
      check(msg.transforms.some((t) => t.child_frame_id === unit && t.parent_frame_id === "base_link"),
            `/tf/mounts has no base_link -> ${unit}`);
    }
    mounts++;
  } else if (topic.startsWith("/scan/")) {
    const unit = topic.slice(6);
    check(schemaOf(m).name === "foxglove.LaserScan", `${topic} schema`);
    check(msg.frame_id === unit, `${topic}: frame ${msg.frame_id}`);
    check(msg.ranges.length === expect.beams[unit],
          `${topic}: ${msg.ranges.length} ranges, the scanner has ${expect.beams[unit]} beams`);
    const span = (expect.beams[unit] - 1) * expect.angular_step[unit];
    check(Math.abs(msg.end_angle - msg.start_angle - span) < 1e-12, `${topic}: angles`);
    check(nsOf(msg.timestamp) <= m.logTime, `${topic}: a scan from the future`);
    if (lastScan[unit] !== undefined) {
      check(m.logTime - lastScan[unit] >= BigInt(expect.scan_period_ns) / 2n,
            `${topic}: scans ${m.logTime - lastScan[unit]} ns apart`);
    }
    lastScan[unit] = m.logTime;
    scans++;
  } else if (topic.startsWith("/signals/")) {
    const unit = topic.slice(9);
    check(row !== undefined, `${topic} at ${m.logTime} ns: no signals.csv row then`);
    for (const [field, value] of Object.entries(msg)) {
      if (field === "timestamp") continue;
      if (Array.isArray(value)) {
        value.forEach((x, k) => {
          const c = column[`${unit}.${field}[${k}]`];
          check(c !== undefined && same(x, row[c]), `${topic}.${field}[${k}] at ${m.logTime} ns`);
        });
      } else {
        const c = column[`${unit}.${field}`] ?? column[`${unit}.${field.replace(/_(\d+)$/, "[$1]")}`];
        check(c !== undefined && same(value, row[c]), `${topic}.${field} at ${m.logTime} ns`);
      }
    }
    signals++;
  } else if (topic === "/scene/static") {
    check(schemaOf(m).name === "foxglove.SceneUpdate", "/scene/static schema");
    const ids = msg.entities.map((e) => e.id);
    for (const id of ["floor", "robot", ...expect.entities]) {
      check(ids.includes(id), `/scene/static has no entity '${id}'`);
    }
    statics++;
  } else if (topic === "/log") {
    // How the run ended, as the last message: its level and the words a
    // viewer's log panel shows.
    check(schemaOf(m).name === "foxglove.Log", "/log schema");
    const level = { ok: 2, interrupted: 3, failed: 4 }[expect.status];
    const word = { ok: "run ended: ok at ", interrupted: "run INTERRUPTED at ",
                   failed: "run FAILED at " }[expect.status];
    check(msg.level === level && msg.message.startsWith(word) && msg.name === "linesim",
          `/log: level ${msg.level}, '${msg.message}' for a run that is ${expect.status}`);
    check(m === indexed[indexed.length - 1] || m.logTime === indexed[indexed.length - 1].logTime,
          "/log is not the last message");
    logs++;
  } else if (topic === "/scene") {
    check(schemaOf(m).name === "foxglove.SceneUpdate", "/scene schema");
    const ids = msg.entities.map((e) => e.id);
    for (const id of expect.belts) check(ids.includes(id), `/scene has no entity '${id}'`);
    for (const e of msg.entities) {
      const c = expect.carried[e.id];
      if (c === undefined) continue;
      // A car body rides its belt: drawn where it was at time zero, in the
      // belt's frame, locked to it.
      const p = e.cubes[0].pose.position;
      check(e.frame_id === c[4] && e.frame_locked === true && p.x === c[0] && p.y === c[1],
            `${e.id}: at (${p.x}, ${p.y}) in ${e.frame_id}, expected (${c[0]}, ${c[1]}) in ${c[4]}`);
      carriedSeen.add(e.id);
    }
    scenes++;
  }
}
// /tf and /signals at every signals.csv row at most every signal period
// (a multiple of the rows' interval in cross_line).
const interval = [...rows.keys()][1] - [...rows.keys()][0];
const every = (BigInt(expect.signal_period_ns) + interval - 1n) / interval;
const logged = BigInt(rows.size - 1) / every + 1n;
check(BigInt(tf) === logged, `${tf} /tf messages for ${rows.size} rows, one in ${every}`);
const units = new Set(header.slice(1).map((h) => h.split(".")[0]));
check(BigInt(signals) === logged * BigInt(units.size),
      `${signals} signal messages for ${logged} rows of ${units.size} units`);
check(statics === 1 && mounts === 1, `${statics} /scene/static, ${mounts} /tf/mounts: one each`);
for (const unit of Object.keys(expect.beams)) {
  check(lastScan[unit] !== undefined, `no scan of ${unit}`);
}
check(carriedSeen.size === Object.keys(expect.carried).length, "a carried object never drawn");
// The same as metadata, found through the summary's metadata index.
check(logs === 1, `${logs} /log messages: one at the end`);
check(reader.metadataIndexes.length === 1 && stats.metadataCount === 1,
      `${reader.metadataIndexes.length} metadata indexes, statistics ${stats.metadataCount}: one`);
check(reader.summaryOffsetsByOpcode.has(0x0d), "no summary offset for the metadata index");
const metadata = [];
for await (const r of reader.readMetadata({ name: "linesim.run" })) metadata.push(r);
check(metadata.length === 1, `${metadata.length} metadata records 'linesim.run'`);
const run = metadata[0].metadata;
check(run.get("status") === expect.status,
      `metadata status '${run.get("status")}', expected ${expect.status}`);
check(Number(run.get("stop_time_s")) === expect.stop_time_s,
      `metadata stop_time_s ${run.get("stop_time_s")}, expected ${expect.stop_time_s}`);
const endTime = Number(run.get("end_time_s"));
check(expect.status === "ok" ? endTime === expect.stop_time_s : endTime < expect.stop_time_s,
      `metadata end_time_s ${endTime} of ${expect.stop_time_s} for a run that is ${expect.status}`);
console.log(`mcap check: ok, ${indexed.length} messages in ${chunks} chunks: ${tf} /tf, ` +
            `${scans} scans, ${scenes} /scene, ${signals} signals, ${statics} /scene/static, ${mounts} /tf/mounts, ` +
            `${logs} /log (${run.get("status")} at ${endTime} s); CRCs of data, summary and every chunk valid`);
