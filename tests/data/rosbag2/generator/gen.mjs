// Writes the rosbag2 test fixtures of tests/data/rosbag2/ from the bundled
// OptiOdom runs (real robot, data/optiodom-2020-06/square/230620202042), with
// independent, widely used writers: MCAP by @mcap/core, CDR by
// @foxglove/rosmsg2-serialization, chunks compressed by @foxglove/wasm-zstd
// and lz4js (LZ4 frame). SQLite3 bags are written by db3.py (Python's
// sqlite3) from the CDR payloads this script dumps.
//   node gen.mjs OUTDIR            fixtures (committed; CI never runs this)
//   node gen.mjs --bench FILE MB   the import benchmark's large recording
// Wheel joint positions: cumulative ticks * 2 pi / ticks_per_rev; ground
// truth: the OptiOdom pose (PoseStamped), the same pose in a world frame
// rotated by 30 deg and shifted by (2, -1) m (TFMessage world -> base_link),
// and /odom integrated from the wheels with the arc integrator.
import crypto from "node:crypto";
import fs from "node:fs";
import path from "node:path";
import { McapWriter } from "@mcap/core";
import { parse } from "@foxglove/rosmsg";
import { MessageWriter } from "@foxglove/rosmsg2-serialization";
import * as zstd from "@foxglove/wasm-zstd";
import lz4js from "lz4js";

const HEADER = `================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec`;
const POSE = `================================================================================
MSG: geometry_msgs/Pose
Point position
Quaternion orientation
================================================================================
MSG: geometry_msgs/Point
float64 x
float64 y
float64 z
================================================================================
MSG: geometry_msgs/Quaternion
float64 x
float64 y
float64 z
float64 w`;
const DEFS = {
  "sensor_msgs/msg/JointState": `std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n${HEADER}`,
  "geometry_msgs/msg/PoseStamped": `std_msgs/Header header\ngeometry_msgs/Pose pose\n${HEADER}\n${POSE}`,
  "nav_msgs/msg/Odometry": `std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\ngeometry_msgs/TwistWithCovariance twist
${HEADER}
================================================================================
MSG: geometry_msgs/PoseWithCovariance
geometry_msgs/Pose pose
float64[36] covariance
================================================================================
MSG: geometry_msgs/TwistWithCovariance
geometry_msgs/Twist twist
float64[36] covariance
================================================================================
MSG: geometry_msgs/Twist
Vector3 linear
Vector3 angular
================================================================================
MSG: geometry_msgs/Vector3
float64 x
float64 y
float64 z
${POSE}`,
  "tf2_msgs/msg/TFMessage": `geometry_msgs/TransformStamped[] transforms
================================================================================
MSG: geometry_msgs/TransformStamped
std_msgs/Header header
string child_frame_id
geometry_msgs/Transform transform
================================================================================
MSG: geometry_msgs/Transform
geometry_msgs/Vector3 translation
geometry_msgs/Quaternion rotation
================================================================================
MSG: geometry_msgs/Vector3
float64 x
float64 y
float64 z
================================================================================
MSG: geometry_msgs/Quaternion
float64 x
float64 y
float64 z
float64 w
${HEADER}`,
  "sensor_msgs/msg/Image": `std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\nuint32 step\nuint8[] data\n${HEADER}`,
};
const writers = {};
for (const [type, def] of Object.entries(DEFS)) writers[type] = new MessageWriter(parse(def, { ros2: true }));

const BASE_S = 1700000000;
const stamp = (ns) => ({ sec: Number(ns / 1000000000n), nanosec: Number(ns % 1000000000n) });
const quat = (yaw) => ({ x: 0, y: 0, z: Math.sin(yaw / 2), w: Math.cos(yaw / 2) });

// Synchronous file sink for McapWriter.
class FileWritable {
  constructor(file) { this.fd = fs.openSync(file, "w"); this.pos = 0n; }
  position() { return this.pos; }
  async write(buf) { fs.writeSync(this.fd, buf); this.pos += BigInt(buf.byteLength); }
  close() { fs.closeSync(this.fd); }
}

async function writeMcap(file, compression, topics, messages, chunkSize = 256 * 1024) {
  const sink = new FileWritable(file);
  const compressChunk = compression === "zstd" ? (d) => ({ compression: "zstd", compressedData: zstd.compress(d, 3) })
    : compression === "lz4" ? (d) => ({ compression: "lz4", compressedData: Uint8Array.from(lz4js.compress(Array.from(d))) })
    : undefined;
  const w = new McapWriter({ writable: sink, useChunks: compression !== "none-unchunked", chunkSize, compressChunk });
  await w.start({ profile: "ros2", library: "umbmark fixtures (@mcap/core)" });
  const channel = {};
  for (const [topic, type] of topics) {
    const schemaId = await w.registerSchema({ name: type, encoding: "ros2msg", data: new TextEncoder().encode(DEFS[type]) });
    channel[topic] = await w.registerChannel({ schemaId, topic, messageEncoding: "cdr", metadata: new Map() });
  }
  let seq = 0;
  for (const m of messages) {
    await w.addMessage({ channelId: channel[m.topic], sequence: seq++, logTime: m.log, publishTime: m.log, data: m.data });
  }
  await w.end();
  sink.close();
}

function readRobotAndRuns(dir) {
  const id = path.basename(dir);
  const meta = Object.fromEntries(fs.readFileSync(path.join(dir, `${id}_metadata.csv`), "utf8").split(/\r?\n/)
    .filter((l) => l).map((l) => { const c = l.split(","); return [c[0], c.slice(1).filter((x) => x !== "")]; }));
  const robot = { b: +meta.Li[0], dR: +meta.Di[0], dL: +meta.Di[1], tpr: +meta.ngear[0] * +meta.encRes[0] };
  const runs = fs.readdirSync(dir).filter((f) => /_run-\d+\.csv$/.test(f)).sort().map((f) =>
    fs.readFileSync(path.join(dir, f), "utf8").split(/\r?\n/).filter((l) => l.trim()).map((l) => l.split(",").map(Number)));
  return { id, robot, runs };
}

// Samples of one run: [t, x, y, theta, ticksR, ticksL] rows, ticks cumulative
// from the run's first row (whose increments belong before the run).
function samples(rows) {
  let cl = 0, cr = 0;
  return rows.map((r, i) => { if (i > 0) { cl += r[5]; cr += r[4]; } return { t: r[0], x: r[1], y: r[2], th: r[3], tl: cl, tr: cr }; });
}

function encode(type, obj) { return writers[type].writeMessage(obj); }

function jointState(ns, posL, posR) {
  return encode("sensor_msgs/msg/JointState", { header: { stamp: stamp(ns), frame_id: "" },
    name: ["left_wheel_joint", "right_wheel_joint", "caster_joint"], position: [posL, posR, 0.5], velocity: [], effort: [] });
}
function poseStamped(ns, x, y, th, frame = "world") {
  return encode("geometry_msgs/msg/PoseStamped", { header: { stamp: stamp(ns), frame_id: frame },
    pose: { position: { x, y, z: 0.05 }, orientation: quat(th) } });
}
const zeros36 = new Array(36).fill(0);
function odometry(ns, x, y, th) {
  return encode("nav_msgs/msg/Odometry", { header: { stamp: stamp(ns), frame_id: "odom" }, child_frame_id: "base_link",
    pose: { pose: { position: { x, y, z: 0 }, orientation: quat(th) }, covariance: zeros36 },
    twist: { twist: { linear: { x: 0, y: 0, z: 0 }, angular: { x: 0, y: 0, z: 0 } }, covariance: zeros36 } });
}
function tf(ns, x, y, th) {
  const t = (child, tx, ty, tth) => ({ header: { stamp: stamp(ns), frame_id: "world" }, child_frame_id: child,
    transform: { translation: { x: tx, y: ty, z: 0 }, rotation: quat(tth) } });
  // A decoy transform first, then the robot.
  return encode("tf2_msgs/msg/TFMessage", { transforms: [t("camera_link", 1, 1, 0), t("base_link", x, y, th)] });
}
// The ground truth in a world frame rotated by 30 deg and shifted by (2, -1).
const ROT = Math.PI / 6;
const world = (x, y, th) => [2 + Math.cos(ROT) * x - Math.sin(ROT) * y, -1 + Math.sin(ROT) * x + Math.cos(ROT) * y, th + ROT];

// Messages of one run starting at t0 ns; wheel positions continue from `start` ticks.
function runMessages(robot, s, t0ns, startTicks, opts) {
  const out = [];
  let ox = 0, oy = 0, oth = 0, pl = 0, pr = 0;
  s.forEach((p, i) => {
    const ns = t0ns + BigInt(Math.round(p.t * 1e9));
    const tl = startTicks.l + p.tl, tr = startTicks.r + p.tr;
    out.push({ topic: "/joint_states", log: ns + 2000000n, data: jointState(ns, (tl * 2 * Math.PI) / robot.tpr, (tr * 2 * Math.PI) / robot.tpr) });
    out.push({ topic: "/mocap/pose", log: ns + 3000000n, data: poseStamped(ns, p.x, p.y, p.th) });
    if (opts.odom) {
      const dl = ((p.tl - pl) * Math.PI * robot.dL) / robot.tpr, dr = ((p.tr - pr) * Math.PI * robot.dR) / robot.tpr;
      pl = p.tl; pr = p.tr;
      const ds = (dl + dr) / 2, dth = (dr - dl) / robot.b, h = dth / 2;
      const chord = Math.abs(h) < 1e-9 ? ds : (ds * Math.sin(h)) / h;
      ox += chord * Math.cos(oth + h); oy += chord * Math.sin(oth + h); oth += dth;
      out.push({ topic: "/odom", log: ns + 1000000n, data: odometry(ns, ox, oy, oth) });
    }
    if (opts.tf) { const [wx, wy, wth] = world(p.x, p.y, p.th); out.push({ topic: "/tf", log: ns + 4000000n, data: tf(ns, wx, wy, wth) }); }
  });
  return out;
}

async function fixtures(outDir) {
  await zstd.isLoaded;
  const repo = path.resolve(path.dirname(new URL(import.meta.url).pathname), "../../../..");
  const { robot, runs } = readRobotAndRuns(path.join(repo, "data/optiodom-2020-06/square/230620202042"));
  fs.mkdirSync(outDir, { recursive: true });
  fs.writeFileSync(path.join(outDir, "robot.toml"), `# OptiOdom robot of dataset 230620202042 (Li, Di, ngear * encRes)\nwheelbase_m = ${robot.b}\n` +
    `wheel_diameter_left_m = ${robot.dL}\nwheel_diameter_right_m = ${robot.dR}\nticks_per_rev = ${robot.tpr}\n`);
  const base = (k) => BigInt(BASE_S + 1000 * k) * 1000000000n;
  const sorted = (m) => m.sort((a, b) => (a.log < b.log ? -1 : a.log > b.log ? 1 : 0));
  // One bag per run (zstd chunks; run 2 lz4); run 1 also carries /odom and /tf.
  const JP = [["/joint_states", "sensor_msgs/msg/JointState"], ["/mocap/pose", "geometry_msgs/msg/PoseStamped"]];
  const kinds = ["zstd", "lz4", "zstd", "zstd", "zstd", "zstd"];
  for (let k = 0; k < runs.length; ++k) {
    const extra = k === 0;
    const topics = [...JP];
    if (extra) topics.push(["/odom", "nav_msgs/msg/Odometry"], ["/tf", "tf2_msgs/msg/TFMessage"]);
    const msgs = sorted(runMessages(robot, samples(runs[k]), base(k), { l: 1000, r: -500 }, { odom: extra, tf: extra }));
    await writeMcap(path.join(outDir, `square_run${k + 1}.mcap`), kinds[k], topics, msgs);
  }
  // The first 200 samples of run 1: unchunked, and in uncompressed chunks (the
  // SQLite3 fixtures hold the same messages).
  const head = sorted(runMessages(robot, samples(runs[0]).slice(0, 200), base(0), { l: 1000, r: -500 }, { odom: false, tf: false }));
  await writeMcap(path.join(outDir, "run1_head_unchunked.mcap"), "none-unchunked", JP, head);
  await writeMcap(path.join(outDir, "run1_head_plain_chunks.mcap"), "none", JP, head, 8192);
  const types = Object.fromEntries(JP);
  fs.writeFileSync(path.join(outDir, "run1_head_payloads.tsv"),
    head.map((m) => `${m.topic}\t${types[m.topic]}\t${m.log}\t${Buffer.from(m.data).toString("hex")}`).join("\n") + "\n");
  // Faulty recordings: a header stamp that goes back; a NaN pose.
  const bad = (mutate) => sorted(runMessages(robot, samples(runs[0]).slice(0, 40).map(mutate), base(0), { l: 0, r: 0 },
    { odom: false, tf: false }));
  await writeMcap(path.join(outDir, "bad_stamps.mcap"), "zstd", JP, bad((p, i) => (i === 20 ? { ...p, t: p.t - 0.2 } : p)));
  await writeMcap(path.join(outDir, "nan_pose.mcap"), "zstd", JP, bad((p, i) => (i === 30 ? { ...p, x: NaN } : p)));
  // One continuous recording: 3 s standing before, between and after the runs
  // (joint states and poses at 20 Hz keep coming); the ground truth jumps to the
  // next run's start pose half-way through each pause.
  const msgs = [];
  let tns = base(10), ticks = { l: 0, r: 0 }, lastPose = null;
  const still = (seconds, pose, nextPose) => {
    for (let i = 0; i < seconds * 20; ++i) {
      const p = nextPose && i >= seconds * 10 ? nextPose : pose;
      msgs.push({ topic: "/joint_states", log: tns, data: jointState(tns, (ticks.l * 2 * Math.PI) / robot.tpr, (ticks.r * 2 * Math.PI) / robot.tpr) });
      msgs.push({ topic: "/mocap/pose", log: tns + 1000n, data: poseStamped(tns, p.x, p.y, p.th) });
      tns += 50000000n;
    }
  };
  [runs[0], runs[3], runs[1]].forEach((rows) => {  // cw, ccw, cw
    const s = samples(rows);
    still(3, lastPose ?? s[0], s[0]);
    const m = runMessages(robot, s, tns - BigInt(Math.round(s[0].t * 1e9)), ticks, { odom: false, tf: false });
    msgs.push(...m);
    const last = s[s.length - 1];
    tns += BigInt(Math.round((last.t - s[0].t) * 1e9)) + 50000000n;
    ticks = { l: ticks.l + last.tl, r: ticks.r + last.tr };
    lastPose = last;
  });
  still(3, lastPose, null);
  await writeMcap(path.join(outDir, "square_continuous.mcap"), "zstd",
    [["/joint_states", "sensor_msgs/msg/JointState"], ["/mocap/pose", "geometry_msgs/msg/PoseStamped"]], sorted(msgs));
}

// The benchmark recording: JointState 100 Hz, PoseStamped 120 Hz, and
// 160x120 rgb8 images at 30 Hz (random bytes: camera noise does not
// compress) until `mb` megabytes; zstd chunks of 4 MB. The robot drives for
// 50 s and stands for 10 s, over and over.
async function bench(file, mb) {
  await zstd.isLoaded;
  const topics = [["/joint_states", "sensor_msgs/msg/JointState"], ["/mocap/pose", "geometry_msgs/msg/PoseStamped"],
    ["/camera/image_raw", "sensor_msgs/msg/Image"]];
  const sink = new FileWritable(file);
  const w = new McapWriter({ writable: sink, useChunks: true, chunkSize: 4 << 20,
    compressChunk: (d) => ({ compression: "zstd", compressedData: zstd.compress(d, 1) }) });
  await w.start({ profile: "ros2", library: "umbmark bench (@mcap/core)" });
  const ch = {};
  for (const [topic, type] of topics) {
    const schemaId = await w.registerSchema({ name: type, encoding: "ros2msg", data: new TextEncoder().encode(DEFS[type]) });
    ch[topic] = await w.registerChannel({ schemaId, topic, messageEncoding: "cdr", metadata: new Map() });
  }
  const img = new Uint8Array(160 * 120 * 3);
  let seq = 0, js = 0, poses = 0;
  const t0 = BigInt(BASE_S) * 1000000000n;
  const limit = BigInt(mb) * 1000000n;
  // 1 ms ticks; a 60 s square cycle: 50 s driving, 10 s standing.
  for (let ms = 0; sink.position() < limit; ++ms) {
    const ns = t0 + BigInt(ms) * 1000000n;
    const cyc = (ms % 60000) / 1000, moving = cyc < 50;
    const s = Math.floor(ms / 60000) * 25 + (moving ? cyc * 0.5 : 25);
    if (ms % 10 === 0) {
      await w.addMessage({ channelId: ch["/joint_states"], sequence: seq++, logTime: ns, publishTime: ns,
        data: jointState(ns, s / 0.042, s / 0.042 + (moving ? Math.sin(cyc) * 0.01 : 0)) }); ++js;
    }
    if (Math.floor((ms + 1) * 0.12) !== Math.floor(ms * 0.12)) {  // 120 Hz
      await w.addMessage({ channelId: ch["/mocap/pose"], sequence: seq++, logTime: ns, publishTime: ns,
        data: poseStamped(ns, Math.cos(cyc), Math.sin(cyc), cyc) }); ++poses;
    }
    if (ms % 33 === 0) {
      crypto.randomFillSync(img);
      await w.addMessage({ channelId: ch["/camera/image_raw"], sequence: seq++, logTime: ns, publishTime: ns,
        data: encode("sensor_msgs/msg/Image", { header: { stamp: stamp(ns), frame_id: "cam" }, height: 120, width: 160,
          encoding: "rgb8", is_bigendian: 0, step: 480, data: img }) });
    }
  }
  await w.end();
  sink.close();
  process.stdout.write(`wrote ${file}: ${sink.position()} bytes, ${js} joint states, ${poses} poses, ${seq - js - poses} images\n`);
}

// Run as a script (gen_robust.mjs imports the writers without running it).
if (path.resolve(process.argv[1] ?? "") === new URL(import.meta.url).pathname) {
  if (process.argv[2] === "--bench") await bench(process.argv[3], Number(process.argv[4] ?? 1100));
  else await fixtures(process.argv[2] ?? path.resolve(path.dirname(new URL(import.meta.url).pathname), ".."));
}

export { DEFS, encode, stamp, quat, writeMcap, zstd };
