// Writes the fixtures of tests/data/rosbag2/lidar/ for `umbmark
// calibrate-lidar`: a differential-drive robot with known wheel radii and
// wheelbase drives ordinary teleop motion (straight runs, spot turns, arcs,
// stops; drawn from a seeded generator and kept inside a safe box) in a
// furnished room; its 2-D lidar, mounted at a known pose (upside down in
// drive_upside.mcap: roll pi, so the beam angles run mirrored) and with a
// known scan clock offset, is ray-cast against the walls (1 cm Gaussian
// range noise, 1/1024 m resolution, 1 % NaN dropouts, +inf beyond range).
// Written with the independent writers: MCAP by @mcap/core, CDR by
// @foxglove/rosmsg2-serialization, zstd chunks by @foxglove/wasm-zstd.
//   node drive_gen.mjs [OUTDIR [FILE...]]   (default ../lidar, every file;
//   FILE... writes only those, keeping the others' truth; CI never runs this)
// The truth of each recording is in OUTDIR/README-truth.json. drive_odom.mcap
// adds the controller's /odom (nav_msgs/Odometry) and a lidar whose ranges
// read 1 % long, for --odometry and --distance-m. drive_still.mcap stands
// still for 40 s: a drive that determines nothing (calibrate-lidar exits 3).
import fs from "node:fs";
import path from "node:path";
import { McapWriter } from "@mcap/core";
import { parse } from "@foxglove/rosmsg";
import { MessageWriter } from "@foxglove/rosmsg2-serialization";
import * as zstd from "@foxglove/wasm-zstd";

const HEADER = `================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec`;
const VEC = `================================================================================
MSG: geometry_msgs/Vector3
float64 x
float64 y
float64 z`;
const QUAT = `================================================================================
MSG: geometry_msgs/Quaternion
float64 x
float64 y
float64 z
float64 w`;
const DEFS = {
  "sensor_msgs/msg/JointState": `std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n${HEADER}`,
  "sensor_msgs/msg/LaserScan": `std_msgs/Header header\nfloat32 angle_min\nfloat32 angle_max\nfloat32 angle_increment
float32 time_increment\nfloat32 scan_time\nfloat32 range_min\nfloat32 range_max\nfloat32[] ranges\nfloat32[] intensities\n${HEADER}`,
  "sensor_msgs/msg/Imu": `std_msgs/Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance
geometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration
float64[9] linear_acceleration_covariance\n${HEADER}\n${QUAT}\n${VEC}`,
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
${VEC}
${QUAT}
${HEADER}`,
  "nav_msgs/msg/Odometry": `std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose
geometry_msgs/TwistWithCovariance twist\n${HEADER}
================================================================================
MSG: geometry_msgs/PoseWithCovariance
geometry_msgs/Pose pose
float64[36] covariance
================================================================================
MSG: geometry_msgs/Pose
geometry_msgs/Point position
geometry_msgs/Quaternion orientation
================================================================================
MSG: geometry_msgs/Point
float64 x
float64 y
float64 z
${QUAT}
================================================================================
MSG: geometry_msgs/TwistWithCovariance
geometry_msgs/Twist twist
float64[36] covariance
================================================================================
MSG: geometry_msgs/Twist
geometry_msgs/Vector3 linear
geometry_msgs/Vector3 angular
${VEC}`,
};
const writers = {};
for (const [type, def] of Object.entries(DEFS)) writers[type] = new MessageWriter(parse(def, { ros2: true }));
const encode = (type, obj) => writers[type].writeMessage(obj);

const BASE_NS = 1700000000n * 1000000000n;
const stamp = (ns) => ({ sec: Number(ns / 1000000000n), nanosec: Number(ns % 1000000000n) });
// Quaternion of R = Rz(yaw) Rx(roll) (URDF rpy with pitch 0).
const quatRpy = (roll, yaw) => ({ x: Math.cos(yaw / 2) * Math.sin(roll / 2), y: Math.sin(yaw / 2) * Math.sin(roll / 2),
  z: Math.sin(yaw / 2) * Math.cos(roll / 2), w: Math.cos(yaw / 2) * Math.cos(roll / 2) });

function rng(seed) {
  let a = seed >>> 0;
  const u = () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
  const n = () => Math.sqrt(-2 * Math.log(u() + 1e-300)) * Math.cos(2 * Math.PI * u());
  return { u, n };
}

// A 7 x 5.5 m room (origin at its centre): a niche, a cupboard, a sofa,
// table legs, a slanted screen and two round pillars [cx, cy, r].
const poly = (pts) => pts.map((p, i) => [...p, ...pts[(i + 1) % pts.length]]);
const box = (x, y, w, h) => poly([[x, y], [x + w, y], [x + w, y + h], [x, y + h]]);
const ROOM = {
  walls: [...poly([[-3.5, -2.75], [3.5, -2.75], [3.5, 2.75], [1.0, 2.75], [1.0, 3.3], [-0.4, 3.3], [-0.4, 2.75], [-3.5, 2.75]]),
    ...box(2.5, -2.65, 0.9, 1.2), ...box(-3.4, 1.6, 1.2, 1.05), ...box(-1.0, -2.5, 0.05, 0.05), ...box(0.1, -2.5, 0.05, 0.05),
    [2.7, 0.6, 3.2, 1.4]],
  pillars: [[2.6, 2.0, 0.15], [-2.8, -2.0, 0.2]],
};
const SAFE = { x: 1.9, y: 1.3 };

function castRay(ox, oy, c, s) {
  let best = Infinity;
  for (const [x1, y1, x2, y2] of ROOM.walls) {
    const ex = x2 - x1, ey = y2 - y1;
    const den = c * ey - s * ex;
    if (Math.abs(den) < 1e-12) continue;
    const t = ((x1 - ox) * ey - (y1 - oy) * ex) / den;
    const u = ((x1 - ox) * s - (y1 - oy) * c) / den;
    if (t > 1e-9 && u >= 0 && u <= 1 && t < best) best = t;
  }
  for (const [cx, cy, r] of ROOM.pillars) {
    const dx = ox - cx, dy = oy - cy;
    const b = dx * c + dy * s, q = dx * dx + dy * dy - r * r;
    const disc = b * b - q;
    if (disc < 0) continue;
    const t = -b - Math.sqrt(disc);
    if (t > 1e-9 && t < best) best = t;
  }
  return best;
}

// Manoeuvres: {ds, dth} together on a trapezoidal progress profile, or a pause.
function pick(R, pose) {
  const inside = (m) => {
    let [x, y, th] = pose;
    for (let k = 1; k <= 20; ++k) {
      const ds = m.ds / 20, dth = m.dth / 20;
      x += ds * Math.cos(th + dth / 2);
      y += ds * Math.sin(th + dth / 2);
      th += dth;
      if (Math.abs(x) > SAFE.x || Math.abs(y) > SAFE.y) return false;
    }
    return true;
  };
  for (let attempt = 0; attempt < 30; ++attempt) {
    const kind = R.u();
    let m = { ds: 0, dth: 0, pause: 0 };
    if (kind < 0.1) m.pause = 0.3 + 1.5 * R.u();
    else if (kind < 0.4) m.ds = (R.u() < 0.85 ? 1 : -0.4) * (0.5 + 2 * R.u());
    else if (kind < 0.6) m.dth = (R.u() < 0.5 ? -1 : 1) * (0.5 + 2.5 * R.u());
    else {
      const radius = 0.3 + 0.9 * R.u(), angle = (R.u() < 0.5 ? -1 : 1) * (1 + 3.5 * R.u());
      m = { ds: radius * Math.abs(angle), dth: angle, pause: 0 };
    }
    if (m.pause > 0 || inside(m)) return m;
  }
  const toCentre = Math.atan2(-pose[1], -pose[0]) - pose[2];
  return { ds: 0, dth: Math.atan2(Math.sin(toCentre), Math.cos(toCentre)), pause: 0 };
}

function progressRates(m, dt) {
  if (m.pause > 0) return new Array(Math.floor(m.pause / dt)).fill(0);
  const lim = (a, v) => (Math.abs(a) > 1e-9 ? v / Math.abs(a) : 1e9);
  const peak = Math.min(lim(m.ds, 0.3), lim(m.dth, 1.2)), acc = Math.min(lim(m.ds, 0.6), lim(m.dth, 2.5));
  const rates = [];
  let u = 0, r = 0;
  while (u < 1) {
    if ((r * r) / (2 * acc) >= 1 - u) r = Math.max(r - acc * dt, 0.02 * peak);
    else r = Math.min(r + acc * dt, peak);
    u += r * dt;
    rates.push(r - Math.max(0, u - 1) / dt);
  }
  return rates;
}

// 1 ms states {phiL, phiR, x, y, th, w} of a drive of `seconds` (3 s still
// first, 2 s still last).
function simulate(robot, seconds, seed, still = false) {
  const R = rng(seed), dt = 0.001, n = Math.round(seconds / dt);
  const v = new Float64Array(n), w = new Float64Array(n);
  let plan = [0, 0, 0], k = still ? n : 3000;
  while (k < n - 2000) {
    const m = pick(R, plan);
    for (const r of progressRates(m, dt)) {
      if (k >= n - 2000) break;
      v[k] = m.ds * r;
      w[k] = m.dth * r;
      plan = [plan[0] + v[k] * dt * Math.cos(plan[2] + 0.5 * w[k] * dt), plan[1] + v[k] * dt * Math.sin(plan[2] + 0.5 * w[k] * dt),
        plan[2] + w[k] * dt];
      ++k;
    }
  }
  const st = { phiL: 0, phiR: 0, x: 0, y: 0, th: 0, w: 0 };
  const out = [{ ...st }];
  for (let i = 0; i < n; ++i) {
    // True wheel travel from the motion; slip noise N(0, k^2 |d|) per wheel.
    const dl0 = (v[i] - 0.5 * w[i] * robot.trueB) * dt, dr0 = (v[i] + 0.5 * w[i] * robot.trueB) * dt;
    st.phiL += (dl0 + robot.k * Math.sqrt(Math.abs(dl0)) * R.n()) / robot.trueRL;
    st.phiR += (dr0 + robot.k * Math.sqrt(Math.abs(dr0)) * R.n()) / robot.trueRR;
    const ds = (dl0 + dr0) / 2, dth = (dr0 - dl0) / robot.trueB;
    st.x += ds * Math.cos(st.th + dth / 2);
    st.y += ds * Math.sin(st.th + dth / 2);
    st.th += dth;
    st.w = dth / dt;
    out.push({ ...st });
  }
  return out;
}

function jointState(ns, l, r) {
  return encode("sensor_msgs/msg/JointState", { header: { stamp: stamp(ns), frame_id: "" },
    name: ["left_wheel_joint", "right_wheel_joint"], position: [l, r], velocity: [], effort: [] });
}
function laserScan(ns, frame, lidar, ranges) {
  return encode("sensor_msgs/msg/LaserScan", { header: { stamp: stamp(ns), frame_id: frame },
    angle_min: lidar.angleMin, angle_max: lidar.angleMin + (lidar.beams - 1) * lidar.inc, angle_increment: lidar.inc,
    time_increment: 0, scan_time: 0.1, range_min: lidar.rangeMin, range_max: lidar.rangeMax,
    ranges: Float32Array.from(ranges), intensities: new Float32Array(0) });
}
const zeros9 = new Array(9).fill(0);
const zeros36 = new Array(36).fill(0);
function odometry(ns, [x, y, th]) {
  return encode("nav_msgs/msg/Odometry", { header: { stamp: stamp(ns), frame_id: "odom" }, child_frame_id: "base_footprint",
    pose: { pose: { position: { x, y, z: 0 }, orientation: quatRpy(0, th) }, covariance: zeros36 },
    twist: { twist: { linear: { x: 0, y: 0, z: 0 }, angular: { x: 0, y: 0, z: 0 } }, covariance: zeros36 } });
}
function imu(ns, rate) {
  return encode("sensor_msgs/msg/Imu", { header: { stamp: stamp(ns), frame_id: "imu_link" },
    orientation: { x: 0, y: 0, z: 0, w: 1 }, orientation_covariance: [-1, 0, 0, 0, 0, 0, 0, 0, 0],
    angular_velocity: { x: 0, y: 0, z: rate }, angular_velocity_covariance: zeros9,
    linear_acceleration: { x: 0, y: 0, z: 9.81 }, linear_acceleration_covariance: zeros9 });
}
function tfStatic(ns, child, [x, y, yaw], roll) {
  return encode("tf2_msgs/msg/TFMessage", { transforms: [
    { header: { stamp: stamp(ns), frame_id: "base_footprint" }, child_frame_id: "base_link",
      transform: { translation: { x: 0, y: 0, z: 0.05 }, rotation: quatRpy(0, 0) } },
    { header: { stamp: stamp(ns), frame_id: "base_link" }, child_frame_id: child,
      transform: { translation: { x, y, z: 0.18 }, rotation: quatRpy(roll, yaw) } }] });
}

function recording(cfg) {
  const states = simulate(cfg.robot, cfg.seconds, cfg.seed, cfg.still);
  const R = rng(cfg.seed + 1);
  const msgs = [];
  const at = (ms) => BASE_NS + BigInt(ms) * 1000000n;
  const offsetNs = BigInt(Math.round(cfg.clockOffsetS * 1e9));
  const [mx, my, myaw] = cfg.mount;
  const lidar = cfg.lidar;
  msgs.push({ topic: cfg.tfTopic, log: at(0), data: tfStatic(at(0), "laser", cfg.tfMount, cfg.upsideDown ? Math.PI : 0) });
  // The controller's odometry (nominal radius 0.033 m and wheelbase 0.28 m,
  // midpoint integration of the joint positions at 50 Hz), when asked for.
  let odom = [0, 0, 0], prevL = 0, prevR = 0;
  states.forEach((s, ms) => {
    if (ms % 20 === 0) msgs.push({ topic: "/joint_states", log: at(ms) + 1000000n, data: jointState(at(ms), s.phiL, s.phiR) });
    if (cfg.odom && ms % 20 === 0) {
      const dl = 0.033 * (s.phiL - prevL), dr = 0.033 * (s.phiR - prevR), ds = (dl + dr) / 2, dth = (dr - dl) / 0.28;
      odom = [odom[0] + ds * Math.cos(odom[2] + dth / 2), odom[1] + ds * Math.sin(odom[2] + dth / 2), odom[2] + dth];
      prevL = s.phiL;
      prevR = s.phiR;
      msgs.push({ topic: "/odom", log: at(ms) + 1200000n, data: odometry(at(ms), odom) });
    }
    if (ms % 10 === 3) {  // 100 Hz gyro: the mean rate over its 10 ms sample
      const wm = ms >= 10 ? (s.th - states[ms - 10].th) / 0.01 : 0;
      msgs.push({ topic: "/imu", log: at(ms) + 500000n, data: imu(at(ms), cfg.imu.scale * wm + cfg.imu.bias + cfg.imu.noise * R.n()) });
    }
    if (ms % 100 === 37) {  // 10 Hz lidar; header stamp = scan time + clock offset
      const c = Math.cos(s.th), sn = Math.sin(s.th);
      const lx = s.x + c * mx - sn * my, ly = s.y + sn * mx + c * my, lth = s.th + myaw;
      const ranges = new Array(lidar.beams);
      for (let i = 0; i < lidar.beams; ++i) {
        const beam = lidar.angleMin + i * lidar.inc;
        const a = lth + (cfg.upsideDown ? -beam : beam);
        const d = castRay(lx, ly, Math.cos(a), Math.sin(a));
        const noisy = (cfg.rangeScale ?? 1) * d + lidar.noise * R.n();
        ranges[i] = R.u() < lidar.dropout ? NaN : d > lidar.rangeMax ? Infinity : Math.round(noisy * 1024) / 1024;
      }
      const t = at(ms) + offsetNs;
      msgs.push({ topic: "/scan", log: t + 3000000n, data: laserScan(t, "laser", lidar, ranges) });
    }
  });
  return msgs.sort((a, b) => (a.log < b.log ? -1 : a.log > b.log ? 1 : 0));
}

class FileWritable {
  constructor(file) { this.fd = fs.openSync(file, "w"); this.pos = 0n; }
  position() { return this.pos; }
  async write(buf) { fs.writeSync(this.fd, buf); this.pos += BigInt(buf.byteLength); }
  close() { fs.closeSync(this.fd); }
}

async function writeMcap(file, topics, messages) {
  const sink = new FileWritable(file);
  const w = new McapWriter({ writable: sink, useChunks: true, chunkSize: 1 << 20,
    compressChunk: (d) => ({ compression: "zstd", compressedData: zstd.compress(d, 19) }) });
  await w.start({ profile: "ros2", library: "umbmark calibrate-lidar fixtures (@mcap/core)" });
  const channel = {};
  for (const [topic, type] of topics) {
    const schemaId = await w.registerSchema({ name: type, encoding: "ros2msg", data: new TextEncoder().encode(DEFS[type]) });
    channel[topic] = await w.registerChannel({ schemaId, topic, messageEncoding: "cdr", metadata: new Map() });
  }
  let seq = 0;
  for (const m of messages)
    await w.addMessage({ channelId: channel[m.topic], sequence: seq++, logTime: m.log, publishTime: m.log, data: m.data });
  await w.end();
  sink.close();
}

// Robot: nominal wheelbase 0.28 m, wheel diameter 0.066 m (radius 0.033);
// truly b = 0.2856 m, D_L = 0.065802 m, D_R = 0.066264 m.
const ROBOT = { trueB: 0.2856, trueRL: 0.032901, trueRR: 0.033132, k: 1e-3 };
const LIDAR = { beams: 180, angleMin: -Math.PI, inc: (2 * Math.PI) / 180, rangeMin: 0.1, rangeMax: 10, noise: 0.01, dropout: 0.01 };
const VARIANTS = [
  // The lidar upside down (roll pi), its scans 35 ms late, /tf_static with a
  // yaw 3 deg off the true one; a gyro with scale 1.012 and bias 0.006 rad/s.
  { file: "drive_upside.mcap", seed: 2901, seconds: 100, mount: [0.10, 0.04, 0.5], tfMount: [0.10, 0.04, 0.5 + (3 * Math.PI) / 180],
    upsideDown: true, clockOffsetS: 0.035, tfTopic: "/tf_static" },
  // Right way up, turned -1.2 rad, scans 20 ms early; /tf_static namespaced
  // as /robot1/tf_static and right.
  { file: "drive_ns.mcap", seed: 2902, seconds: 100, mount: [-0.06, 0.02, -1.2], tfMount: [-0.06, 0.02, -1.2],
    upsideDown: false, clockOffsetS: -0.02, tfTopic: "/robot1/tf_static" },
  // For --odometry and --distance-m: the controller's /odom beside
  // /joint_states, and a lidar whose ranges read 1 % long (so the scale
  // from the ranges is 1 % off and a measured distance corrects it); the
  // first seed from 2903 whose drive ends at least 1.5 m from its start.
  { file: "drive_odom.mcap", seed: 2903, seconds: 100, mount: [0.08, -0.03, 0.2], tfMount: [0.08, -0.03, 0.2],
    upsideDown: false, clockOffsetS: 0.01, tfTopic: "/tf_static", odom: true, rangeScale: 1.01, minEndDistance: 1.5 },
  // Standing still for 40 s (long enough not to be refused as short): the
  // drive determines none of the parameters.
  { file: "drive_still.mcap", seed: 2904, seconds: 40, mount: [0.08, -0.03, 0.2], tfMount: [0.08, -0.03, 0.2],
    upsideDown: false, clockOffsetS: 0.0, tfTopic: "/tf_static", still: true },
];

await zstd.isLoaded;
const outDir = process.argv[2] ?? path.resolve(path.dirname(new URL(import.meta.url).pathname), "../lidar");
fs.mkdirSync(outDir, { recursive: true });
fs.writeFileSync(path.join(outDir, "robot.toml"),
  "# the parameters the odometry uses (nominal) for drive_*.mcap\nwheelbase_m = 0.28\nwheel_diameter_left_m = 0.066\nwheel_diameter_right_m = 0.066\n");
const only = process.argv.slice(3);
const truthFile = path.join(outDir, "README-truth.json");
const truth = only.length > 0 && fs.existsSync(truthFile) ? JSON.parse(fs.readFileSync(truthFile, "utf8")) : {};
for (const v of VARIANTS) {
  if (only.length > 0 && !only.includes(v.file)) continue;
  while (v.minEndDistance) {  // the first seed whose drive ends far enough from its start
    const end = simulate(ROBOT, v.seconds, v.seed).at(-1);
    if (Math.hypot(end.x, end.y) >= v.minEndDistance) break;
    ++v.seed;
  }
  const msgs = recording({ ...v, robot: ROBOT, lidar: LIDAR, imu: { scale: 1.012, bias: 0.006, noise: 0.004 } });
  const topics = [["/joint_states", "sensor_msgs/msg/JointState"], ["/scan", "sensor_msgs/msg/LaserScan"],
    ["/imu", "sensor_msgs/msg/Imu"], [v.tfTopic, "tf2_msgs/msg/TFMessage"]];
  if (v.odom) topics.push(["/odom", "nav_msgs/msg/Odometry"]);
  await writeMcap(path.join(outDir, v.file), topics, msgs);
  truth[v.file] = { wheelbase_m: ROBOT.trueB, wheel_diameter_left_m: 2 * ROBOT.trueRL, wheel_diameter_right_m: 2 * ROBOT.trueRR,
    mount: v.mount, upside_down: v.upsideDown, scan_time_offset_s: v.clockOffsetS, gyro_scale: 1.012, gyro_bias_rad_s: 0.006,
    tf_static: { topic: v.tfTopic, mount: v.tfMount } };
  if (v.minEndDistance) {
    const end = simulate(ROBOT, v.seconds, v.seed).at(-1);
    Object.assign(truth[v.file], { seed: v.seed, distance_start_end_m: Math.hypot(end.x, end.y), lidar_range_scale: v.rangeScale });
  }
  process.stdout.write(`wrote ${v.file}: ${msgs.filter((m) => m.topic === "/scan").length} scans\n`);
}
fs.writeFileSync(truthFile, JSON.stringify(truth, null, 2) + "\n");
