// Independent check of a fahr recording with Foxglove's own npm packages:
// @mcap/core reads the file (stream and indexed readers, every chunk CRC),
// @foxglove/crc checks the data-section and summary CRCs, @mcap/support
// decompresses, @foxglove/omgidl-parser + omgidl-serialization decode every
// message with the schema stored in the file. Prints one JSON object:
// per channel counts, a decoded sample of each type, and per writer
// (topic, writer_id) the loss accounting checked against the writer's own
// sent count from its last ServiceStatus.
//
//   node check_mcap.mjs FILE.mcap
import { readFileSync } from "node:fs";
import { crc32 } from "@foxglove/crc";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { loadDecompressHandlers } from "@mcap/support";
import { parseIDL } from "@foxglove/omgidl-parser";
import { MessageReader } from "@foxglove/omgidl-serialization";

const path = process.argv[2];
const bytes = readFileSync(path);
const decompressHandlers = await loadDecompressHandlers();
const problems = [];
const json = (v) => JSON.stringify(v, (_k, x) => (typeof x === "bigint" ? Number(x) : x));

// 1. Stream reader: every record in file order, chunk CRCs validated.
const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true, includeChunks: true });
stream.append(bytes);
const schemas = new Map();
const channels = new Map();
const counts = new Map();
let dataEndCrc, footer, chunkCrcs = 0, metadata = [];
for (let r; (r = stream.nextRecord()); ) {
  if (r.type === "Schema") schemas.set(r.id, r);
  else if (r.type === "Channel") channels.set(r.id, r);
  else if (r.type === "Chunk" && r.uncompressedCrc !== 0) chunkCrcs++;
  else if (r.type === "DataEnd") dataEndCrc = r.dataSectionCrc;
  else if (r.type === "Footer") footer = r;
  else if (r.type === "Metadata") metadata.push(r);
}
if (!stream.done()) problems.push("stream reader did not reach the end of the file");

// 2. The data section's and the summary's CRCs, computed here.
const dataEnd = findDataEnd(bytes);
if (dataEndCrc === undefined || dataEndCrc === 0) problems.push("no data section CRC");
else if (crc32(bytes.subarray(0, dataEnd)) !== dataEndCrc) problems.push("data section CRC mismatch");
if (!footer || footer.summaryCrc === 0) problems.push("no summary CRC");
else {
  const footerStart = bytes.length - 8 - (1 + 8 + 20);
  const summaryStart = Number(footer.summaryStart);
  const crc = crc32(bytes.subarray(summaryStart, footerStart + 1 + 8 + 16));
  if (crc !== footer.summaryCrc) problems.push("summary CRC mismatch");
}

// 3. Indexed reader: every message through the chunk indexes, CRCs validated.
const readable = {
  size: async () => BigInt(bytes.length),
  read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
};
const indexed = await McapIndexedReader.Initialize({ readable, decompressHandlers });
const readers = new Map();
for (const [id, s] of indexed.schemasById) {
  if (s.encoding !== "omgidl") problems.push(`schema ${s.name}: encoding ${s.encoding}`);
  const text = new TextDecoder().decode(s.data);
  if (/^\s*#/m.test(text)) problems.push(`schema ${s.name} has preprocessor lines`);
  readers.set(id, new MessageReader(s.name, parseIDL(text)));
}
const samples = {};
const writers = new Map();  // "topic writer_id" -> {seqs, sent}
const lastStatus = new Map();  // writer_id -> decoded ServiceStatus
let decoded = 0;
for await (const m of indexed.readMessages({ validateCrcs: true })) {
  const channel = indexed.channelsById.get(m.channelId);
  counts.set(channel.topic, (counts.get(channel.topic) ?? 0) + 1);
  const value = readers.get(channel.schemaId).readMessage(m.data);
  decoded++;
  const h = value.header;
  if (Number(h.seq) % 2 ** 32 !== m.sequence) problems.push(`${channel.topic}: sequence != header.seq`);
  if (BigInt(h.source_time_ns) !== m.publishTime) problems.push(`${channel.topic}: publish_time != source time`);
  const key = `${channel.topic} ${h.writer_id}`;
  if (!writers.has(key)) writers.set(key, { topic: channel.topic, writer_id: h.writer_id, seqs: [] });
  writers.get(key).seqs.push(Number(h.seq));
  if (channel.topic === "fahr/ServiceStatus") lastStatus.set(h.writer_id, value);
  if (!samples[channel.topic]) samples[channel.topic] = summarise(value);
}

if (decoded === 0) problems.push("no messages");

// 4. Loss accounting: the recorder's figures (its fahr_recording_loss
// metadata) against what is in the file and what each writer says it sent.
const loss = metadata.find((m) => m.name === "fahr_recording_loss");
const accounting = [];
if (!loss) problems.push("no fahr_recording_loss metadata");
else {
  for (const [k, v] of loss.metadata) {
    const [topic, writerId] = k.split(" ");
    const [sent, recorded, gaps, drops, skipped, leading] = v.split(" ").map(Number);
    const w = writers.get(`${topic} ${writerId}`);
    const inFile = w ? w.seqs.length : 0;
    const status = lastStatus.get(Number(writerId));
    const metric = status?.metrics.find((x) => x.name === `sent ${topic}`);
    const reported = metric ? metric.value : undefined;
    const row = { topic, writer_id: Number(writerId), sent, reported, recorded, in_file: inFile, gaps, leading_gaps: leading, drops, skipped };
    accounting.push(row);
    if (inFile !== recorded) problems.push(`${k}: ${inFile} in the file, recorder says ${recorded}`);
    if (recorded + gaps + drops + skipped !== sent) problems.push(`${k}: recorded + gaps + drops + skipped != sent`);
    // The gaps again, from the sequence numbers in the file.
    if (w && skipped === 0) {
      const seen = new Set(w.seqs);
      let missing = 0;
      for (let s = 1; s <= sent; s++) if (!seen.has(s)) missing++;
      if (missing !== gaps + drops) problems.push(`${k}: ${missing} sequence numbers missing from the file, recorder says ${gaps} gaps + ${drops} drops`);
    }
    // A status carries the counts from before it was written: its own topic
    // and ServiceEvents (written right after it) are one behind.
    const behind = topic === "fahr/ServiceStatus" || topic === "fahr/ServiceEvents" ? 1 : 0;
    // A participant without a status reporter (the lockstep clock, a
    // replay) reports no count; one with a reporter must.
    if (reported === undefined && status) problems.push(`${k}: the writer reported no sent count`);
    else if (reported === undefined) row.reported = "no ServiceStatus";
    else if (reported !== undefined && reported + behind !== sent) problems.push(`${k}: writer reports ${reported} sent, recorder counts ${sent}`);
    if (w && new Set(w.seqs).size !== w.seqs.length) problems.push(`${k}: duplicate sequence numbers`);
  }
}

console.log(json({
  file: path, ok: problems.length === 0, problems,
  messages: decoded, statistics_messages: indexed.statistics?.messageCount,
  chunk_crcs: chunkCrcs, schemas: [...schemas.values()].map((s) => s.name),
  channels: Object.fromEntries(counts), metadata: metadata.map((m) => m.name),
  accounting, samples,
}));
process.exitCode = problems.length === 0 ? 0 : 1;

function findDataEnd(b) {
  // Walk the records from the magic to the Data End record (opcode 0x0f).
  let pos = 8;
  const view = new DataView(b.buffer, b.byteOffset, b.byteLength);
  while (pos + 9 <= b.length) {
    const op = b[pos];
    const len = Number(view.getBigUint64(pos + 1, true));
    if (op === 0x0f) return pos;
    pos += 9 + len;
  }
  return b.length;
}

function summarise(value) {
  // Scalars and short arrays as they are; long arrays by length.
  const out = {};
  for (const [k, v] of Object.entries(value)) {
    if (ArrayBuffer.isView(v) || Array.isArray(v)) out[k] = v.length > 8 ? `[${v.length} items]` : Array.from(v);
    else out[k] = v;
  }
  return out;
}
