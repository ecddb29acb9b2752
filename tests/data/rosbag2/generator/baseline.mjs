// Baseline for scripts/bench_rosbag2.sh: the Node MCAP reader (@mcap/core's
// McapStreamReader, zstd by @foxglove/wasm-zstd) decoding the CDR of the two
// topics the importer uses (@foxglove/rosmsg2-serialization), streaming the
// file in 4 MB reads. Prints MB/s and messages/s.
//   node baseline.mjs FILE.mcap
import fs from "node:fs";
import { McapStreamReader } from "@mcap/core";
import { parse } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import * as zstd from "@foxglove/wasm-zstd";
import lz4 from "@foxglove/wasm-lz4";

await zstd.isLoaded;
await lz4.isLoaded;
const file = process.argv[2];
const t0 = process.hrtime.bigint();
const reader = new McapStreamReader({
  decompressHandlers: { zstd: (buf, size) => zstd.decompress(buf, Number(size)), lz4: (buf, size) => lz4(buf, Number(size)) },
});
const schemas = new Map(), readers = new Map();
const wanted = new Set(["/joint_states", "/mocap/pose"]);
let messages = 0, check = 0;
const fd = fs.openSync(file, "r");
const buf = Buffer.alloc(4 << 20);
for (;;) {
  const n = fs.readSync(fd, buf, 0, buf.length, null);
  if (n === 0) break;
  reader.append(buf.subarray(0, n));
  for (let rec; (rec = reader.nextRecord()); ) {
    if (rec.type === "Schema") schemas.set(rec.id, rec);
    else if (rec.type === "Channel" && wanted.has(rec.topic)) {
      const s = schemas.get(rec.schemaId);
      readers.set(rec.id, new MessageReader(parse(new TextDecoder().decode(s.data), { ros2: true })));
    } else if (rec.type === "Message") {
      const r = readers.get(rec.channelId);
      if (r) { const m = r.readMessage(rec.data); check += m.header.stamp.nanosec & 1; ++messages; }
    }
  }
}
const s = Number(process.hrtime.bigint() - t0) / 1e9;
const mb = fs.statSync(file).size / 1e6;
console.log(`node baseline: ${mb.toFixed(1)} MB in ${s.toFixed(3)} s = ${(mb / s).toFixed(1)} MB/s, ${messages} messages decoded = ${(messages / s).toFixed(0)} messages/s (check ${check})`);
