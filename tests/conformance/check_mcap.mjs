// Independent conformance check of a rover MCAP flight log.
//
// Reads FILE twice with the reference JavaScript MCAP library (@mcap/core):
// once through the summary and indexes (McapIndexedReader) and once as a
// linear stream (McapStreamReader), both with CRC validation. Messages are
// decoded with @foxglove/rosmsg2-serialization from the ros2msg schema text
// stored in the file, so schema text and CDR bytes are checked together.
// Everything is compared against EXPECTED.json, written by the C++ test that
// produced the log.
//
// usage: node check_mcap.mjs FILE [EXPECTED.json]
// Without EXPECTED.json it checks only that both readers agree, that CRCs
// hold, and that every message decodes from its schema with no bytes left
// over, then prints one line per channel.
// exit status 0 when everything matches; otherwise every mismatch is listed.
import { open, readFile } from "node:fs/promises";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { parse as parseRosmsg } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import * as zstd from "@foxglove/wasm-zstd";
import lz4 from "@foxglove/wasm-lz4";

const [file, expectedFile] = process.argv.slice(2);
if (!file) {
  console.error("usage: node check_mcap.mjs FILE [EXPECTED.json]");
  process.exit(2);
}

await zstd.isLoaded;
await lz4.isLoaded;
const decompressHandlers = {
  zstd: (buffer, size) => zstd.decompress(buffer, Number(size)),
  lz4: (buffer, size) => lz4(buffer, Number(size)),
};

const failures = [];
const fail = (what) => failures.push(what);
const expected = expectedFile
  ? JSON.parse(await readFile(expectedFile, "utf8"))
  : { profile: "ros2", channels: null, samples: [] };

// --- indexed read (summary, chunk indexes, message indexes) ---
const handle = await open(file, "r");
const readable = {
  size: async () => BigInt((await handle.stat()).size),
  read: async (offset, size) => {
    const buf = new Uint8Array(Number(size));
    const { bytesRead } = await handle.read(buf, 0, Number(size), Number(offset));
    if (bytesRead !== Number(size)) throw new Error(`short read at ${offset}`);
    return buf;
  },
};
const indexed = await McapIndexedReader.Initialize({ readable, decompressHandlers });
if (indexed.header.profile !== expected.profile) {
  fail(`header.profile: expected "${expected.profile}", found "${indexed.header.profile}"`);
}

const channelsByTopic = new Map();
for (const channel of indexed.channelsById.values()) channelsByTopic.set(channel.topic, channel);

const decoders = new Map();
function decoderFor(channel) {
  if (!decoders.has(channel.id)) {
    const schema = indexed.schemasById.get(channel.schemaId);
    const text = new TextDecoder().decode(schema.data);
    decoders.set(channel.id, new MessageReader(parseRosmsg(text, { ros2: true })));
  }
  return decoders.get(channel.id);
}

const indexedCounts = new Map();
const indexedMessages = new Map();  // topic -> [{logTime, message}]
for await (const msg of indexed.readMessages({ validateCrcs: true })) {
  const channel = indexed.channelsById.get(msg.channelId);
  const list = indexedMessages.get(channel.topic) ?? [];
  list.push(msg);
  indexedMessages.set(channel.topic, list);
  indexedCounts.set(channel.topic, (indexedCounts.get(channel.topic) ?? 0) + 1);
}
await handle.close();

// --- linear stream read, independent of the summary ---
const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
stream.append(await readFile(file));
const streamCounts = new Map();
const streamChannels = new Map();
let sawFooter = false;
for (let record; (record = stream.nextRecord()); ) {
  if (record.type === "Channel") streamChannels.set(record.id, record);
  if (record.type === "Message") {
    const topic = streamChannels.get(record.channelId).topic;
    streamCounts.set(topic, (streamCounts.get(topic) ?? 0) + 1);
  }
  if (record.type === "Footer") sawFooter = true;
}
if (!sawFooter) fail("stream reader: no Footer record");
if (!stream.done()) fail("stream reader: bytes left after the trailing magic");

// --- without expectations: both readers agree and every message decodes ---
if (expected.channels === null) {
  expected.channels = [];
  for (const [topic, msgs] of indexedMessages) {
    if ((streamCounts.get(topic) ?? 0) !== msgs.length) {
      fail(`channel ${topic}: stream reader read ${streamCounts.get(topic) ?? 0}, indexed reader ${msgs.length}`);
    }
    const reader = decoderFor(channelsByTopic.get(topic));
    for (const [i, msg] of msgs.entries()) {
      try {
        reader.readMessage(msg.data);
        if (reader.lastReadHadTrailingBytes()) { fail(`${topic}[${i}]: trailing bytes after decoding`); break; }
      } catch (e) {
        fail(`${topic}[${i}]: CDR decode failed: ${e.message}`);
        break;
      }
    }
    const schema = indexed.schemasById.get(channelsByTopic.get(topic).schemaId);
    console.log(`  ${topic.padEnd(28)} ${schema.name.padEnd(36)} ${String(msgs.length).padStart(8)} decoded`);
  }
}

// --- channels, schemas, counts, time ranges ---
for (const want of expected.channels) {
  const channel = channelsByTopic.get(want.topic);
  if (!channel) { fail(`channel ${want.topic}: missing`); continue; }
  const schema = indexed.schemasById.get(channel.schemaId);
  const where = `channel ${want.topic}`;
  if (channel.messageEncoding !== want.message_encoding) fail(`${where}: message_encoding "${channel.messageEncoding}", expected "${want.message_encoding}"`);
  if (schema?.name !== want.schema) fail(`${where}: schema "${schema?.name}", expected "${want.schema}"`);
  if (schema?.encoding !== want.schema_encoding) fail(`${where}: schema encoding "${schema?.encoding}", expected "${want.schema_encoding}"`);
  const statCount = indexed.statistics?.channelMessageCounts.get(channel.id);
  if (statCount !== BigInt(want.count)) fail(`${where}: statistics count ${statCount}, expected ${want.count}`);
  if ((indexedCounts.get(want.topic) ?? 0) !== want.count) fail(`${where}: indexed reader read ${indexedCounts.get(want.topic) ?? 0} messages, expected ${want.count}`);
  if ((streamCounts.get(want.topic) ?? 0) !== want.count) fail(`${where}: stream reader read ${streamCounts.get(want.topic) ?? 0} messages, expected ${want.count}`);
  const msgs = indexedMessages.get(want.topic) ?? [];
  if (msgs.length) {
    // Times are optional in the expectations (records stamped by the wall clock).
    if (want.first_log_time_ns !== undefined && msgs[0].logTime !== BigInt(want.first_log_time_ns)) fail(`${where}: first log_time ${msgs[0].logTime}, expected ${want.first_log_time_ns}`);
    if (want.last_log_time_ns !== undefined && msgs.at(-1).logTime !== BigInt(want.last_log_time_ns)) fail(`${where}: last log_time ${msgs.at(-1).logTime}, expected ${want.last_log_time_ns}`);
    for (let i = 1; i < msgs.length; ++i) {
      if (msgs[i].logTime < msgs[i - 1].logTime) { fail(`${where}: log_time goes back at message ${i}`); break; }
    }
  }
}
if (expectedFile && expected.channels.length !== channelsByTopic.size) fail(`file has ${channelsByTopic.size} channels, expected ${expected.channels.length}`);

// --- decoded fields of selected messages ---
function lookup(value, path) {
  for (const part of path.split(".")) {
    if (value === undefined || value === null) return undefined;
    value = value[/^\d+$/.test(part) ? Number(part) : part];
  }
  return value;
}
for (const sample of expected.samples) {
  const where = `${sample.topic}[${sample.index}]`;
  const msg = (indexedMessages.get(sample.topic) ?? [])[sample.index];
  if (!msg) { fail(`${where}: no such message`); continue; }
  if (msg.logTime !== BigInt(sample.log_time_ns)) fail(`${where}: log_time ${msg.logTime}, expected ${sample.log_time_ns}`);
  const reader = decoderFor(indexed.channelsById.get(msg.channelId));
  let decoded;
  try {
    decoded = reader.readMessage(msg.data);
  } catch (e) {
    fail(`${where}: CDR decode failed: ${e.message}`);
    continue;
  }
  if (reader.lastReadHadTrailingBytes()) fail(`${where}: trailing bytes after decoding (schema/payload mismatch)`);
  for (const [path, want] of Object.entries(sample.fields)) {
    let got = lookup(decoded, path);
    if (got instanceof Uint8Array || Array.isArray(got)) got = Array.from(got);
    if (typeof got === "bigint") got = got.toString();
    if (JSON.stringify(got) !== JSON.stringify(want)) {
      fail(`${where}.${path}: found ${JSON.stringify(got)}, expected ${JSON.stringify(want)}`);
    }
  }
}

const total = [...indexedCounts.values()].reduce((a, b) => a + b, 0);
if (failures.length) {
  console.error(`FAIL ${file}: ${failures.length} mismatch(es)`);
  for (const f of failures) console.error("  " + f);
  process.exit(1);
}
console.log(expectedFile
  ? `OK ${file}: ${channelsByTopic.size} channels, ${total} messages, ${expected.samples.length} decoded samples match`
  : `OK ${file}: ${channelsByTopic.size} channels, ${total} messages read by @mcap/core (indexed and stream, CRCs checked) and decoded`);
