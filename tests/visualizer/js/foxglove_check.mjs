// A Foxglove WebSocket client (@foxglove/ws-protocol over `ws`) against
// fahr_visualizer: every advertised channel must be `cdr` with an `omgidl`
// schema; it subscribes to all of them and decodes samples with
// @foxglove/omgidl-serialization, the schema as advertised. Then it checks
// that client publishing is refused (the station does not allow remote input).
//   node foxglove_check.mjs ws://HOST:PORT TIMEOUT_S TYPES
// TYPES: comma-separated short type names that must each decode at least once.
// Prints one JSON line; exit 0 if every check passed.
import wsProtocol from "@foxglove/ws-protocol";
import { parseIDL } from "@foxglove/omgidl-parser";
import { MessageReader } from "@foxglove/omgidl-serialization";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol;

const [url, timeoutText, typesText] = process.argv.slice(2);
const needed = new Set((typesText ?? "").split(",").filter(Boolean));
const problems = [];
const decoded = {};
const example = {};
const readers = new Map();
const topicsByChannel = new Map();
let statusRefusal = null;

const client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
client.on("error", (e) => problems.push(`socket error: ${e?.message ?? e}`));
client.on("serverInfo", (info) => {
  if (info.capabilities.includes("clientPublish")) problems.push("the server offers clientPublish without remote input");
});
client.on("status", (s) => {
  if (s.level === 2 && /refused/.test(s.message)) statusRefusal = s.message;
});
client.on("advertise", (channels) => {
  for (const ch of channels) {
    if (ch.encoding !== "cdr") problems.push(`${ch.topic}: encoding ${ch.encoding}`);
    if (ch.schemaEncoding !== "omgidl") problems.push(`${ch.topic}: schemaEncoding ${ch.schemaEncoding}`);
    try {
      const reader = new MessageReader(ch.schemaName, parseIDL(ch.schema));
      const sub = client.subscribe(ch.id);
      readers.set(sub, reader);
      topicsByChannel.set(sub, ch.schemaName.split("::").pop());
    } catch (e) {
      problems.push(`${ch.topic}: schema does not parse: ${e.message}`);
    }
  }
  // A client channel must be refused: this station does not allow remote input.
  client.advertise({ topic: "fahr/RemoteInput", encoding: "cdr", schemaName: "fahr::msg::DevicePose" });
});
client.on("message", ({ subscriptionId, data }) => {
  const reader = readers.get(subscriptionId);
  const type = topicsByChannel.get(subscriptionId);
  try {
    const m = reader.readMessage(new Uint8Array(data.buffer, data.byteOffset, data.byteLength));
    decoded[type] = (decoded[type] ?? 0) + 1;
    if (!example[type]) example[type] = { seq: String(m.header.seq), writer_id: m.header.writer_id };
  } catch (e) {
    problems.push(`${type}: a sample does not decode: ${e.message}`);
  }
});

const deadline = Date.now() + Number(timeoutText ?? 30) * 1000;
while (Date.now() < deadline) {
  await new Promise((r) => setTimeout(r, 200));
  const all = [...needed].every((t) => decoded[t] > 0);
  if (all && statusRefusal) break;
}
client.close();
for (const t of needed) if (!(decoded[t] > 0)) problems.push(`no ${t} decoded`);
if (!statusRefusal) problems.push("client publishing was not refused");
console.log(JSON.stringify({ decoded, example, refusal: statusRefusal, problems }));
process.exit(problems.length === 0 ? 0 : 1);
