// Writes tests/data/rosbag2/robust/: recordings as real robots make them
// (issue 23), from a simulated differential-drive robot with known true
// parameters, with the same independent writers as gen.mjs (@mcap/core,
// @foxglove/rosmsg2-serialization, @foxglove/wasm-zstd).
//   node gen_robust.mjs [OUTDIR]      (default ../robust; CI never runs this)
// The robot: robot file (nominal) wheelbase 0.2 m, wheel diameters 0.084 m;
// true wheelbase 0.204 m, left 0.0842 m, right 0.0838 m. It drives one cw
// and one ccw 1 m square by its nominal odometry (20 Hz; legs 0.25 m/s,
// turns in place ~0.8 rad/s; 3 s standing before, between and after).
// Topics: /joint_states (left_wheel_joint, right_wheel_joint and a moving
// left_right_arm), /mocap/pose (the true axle pose, 0.2 mm / 0.5 mrad
// noise, seed 23), /odom (the robot's odometry, nominal parameters), /tf
// (odom -> base_link from the odometry; world -> mocap_marker from the
// motion capture, the marker 8 cm ahead, 3 cm left, turned 0.1 rad) and
// /tf_static (mocap_marker -> mocap_base: the axle, and base_link -> laser).
import fs from "node:fs";
import path from "node:path";
import { encode, stamp, quat, writeMcap, zstd } from "./gen.mjs";

const NOMINAL = { b: 0.2, dl: 0.084, dr: 0.084 };
const TRUE = { b: 0.204, dl: 0.0842, dr: 0.0838 };
const HZ = 20;
const BASE_S = 1700000000n;
const MARKER = { x: 0.08, y: 0.03, th: 0.1 };

// Mulberry32: a seeded uniform generator; normal by Box-Muller.
function rng(seed) {
  let a = seed >>> 0;
  const u = () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
  return () => Math.sqrt(-2 * Math.log(u() + 1e-12)) * Math.cos(2 * Math.PI * u());
}

function step(p, dl, dr, b) {
  const ds = (dl + dr) / 2, dth = (dr - dl) / b, h = dth / 2;
  const chord = Math.abs(h) < 1e-9 ? ds : (ds * Math.sin(h)) / h;
  return { x: p.x + chord * Math.cos(p.th + h), y: p.y + chord * Math.sin(p.th + h), th: p.th + dth };
}
const compose = (a, b) => ({ x: a.x + Math.cos(a.th) * b.x - Math.sin(a.th) * b.y,
  y: a.y + Math.sin(a.th) * b.x + Math.cos(a.th) * b.y, th: a.th + b.th });
const inverse = (a) => ({ x: -Math.cos(a.th) * a.x - Math.sin(a.th) * a.y, y: Math.sin(a.th) * a.x - Math.cos(a.th) * a.y, th: -a.th });

// Samples: t [s], wheel angles [rad], true pose, nominal odometry pose.
function simulate() {
  const cmds = [];  // per step: [wheel angle increments left, right]
  const stand = (s) => { for (let i = 0; i < s * HZ; ++i) cmds.push([0, 0]); };
  const leg = () => { const n = 4 * HZ, a = 1 / (NOMINAL.dl / 2) / n; for (let i = 0; i < n; ++i) cmds.push([a, a]); };
  const turn = (sign) => {
    const n = 40, a = ((NOMINAL.b / 2) * (Math.PI / 2)) / (NOMINAL.dl / 2) / n;
    for (let i = 0; i < n; ++i) cmds.push([-sign * a, sign * a]);
  };
  stand(3);
  for (const sign of [-1, 1]) {  // cw, then ccw
    for (let k = 0; k < 4; ++k) { leg(); turn(sign); }
    stand(3);
  }
  const noise = rng(23);
  const out = [];
  let wl = 0, wr = 0, truth = { x: 0, y: 0, th: 0 }, odo = { x: 0, y: 0, th: 0 };
  cmds.forEach(([al, ar], i) => {
    if (i > 0) {
      wl += al; wr += ar;
      truth = step(truth, (al * TRUE.dl) / 2, (ar * TRUE.dr) / 2, TRUE.b);
      odo = step(odo, (al * NOMINAL.dl) / 2, (ar * NOMINAL.dr) / 2, NOMINAL.b);
    }
    const mocap = { x: truth.x + 2e-4 * noise(), y: truth.y + 2e-4 * noise(), th: truth.th + 5e-4 * noise() };
    out.push({ t: i / HZ, wl, wr, arm: 0.3 * Math.sin(i / 50), truth, mocap, odo });
  });
  return out;
}

const ns = (t) => BASE_S * 1000000000n + BigInt(Math.round(t * 1e9));
function jointState(t, s, o = {}) {
  return encode("sensor_msgs/msg/JointState", { header: { stamp: stamp(o.stamp ?? ns(t)), frame_id: "" },
    name: o.names ?? ["left_right_arm", "left_wheel_joint", "right_wheel_joint"],
    position: o.position ?? [s.arm, s.wl, s.wr], velocity: o.velocity ?? [], effort: [] });
}
function poseStamped(stampNs, p) {
  return encode("geometry_msgs/msg/PoseStamped", { header: { stamp: stamp(stampNs), frame_id: "world" },
    pose: { position: { x: p.x, y: p.y, z: 0.1 }, orientation: quat(p.th) } });
}
const zeros36 = new Array(36).fill(0);
function odometry(stampNs, p) {
  return encode("nav_msgs/msg/Odometry", { header: { stamp: stamp(stampNs), frame_id: "odom" }, child_frame_id: "base_link",
    pose: { pose: { position: { x: p.x, y: p.y, z: 0 }, orientation: quat(p.th) }, covariance: zeros36 },
    twist: { twist: { linear: { x: 0, y: 0, z: 0 }, angular: { x: 0, y: 0, z: 0 } }, covariance: zeros36 } });
}
function tfMessage(stampNs, list) {
  return encode("tf2_msgs/msg/TFMessage", { transforms: list.map(([parent, child, p]) => ({
    header: { stamp: stamp(stampNs), frame_id: parent }, child_frame_id: child,
    transform: { translation: { x: p.x, y: p.y, z: 0 }, rotation: quat(p.th) } })) });
}

const JS = ["/joint_states", "sensor_msgs/msg/JointState"], MOCAP = ["/mocap/pose", "geometry_msgs/msg/PoseStamped"];
const sorted = (m) => m.sort((a, b) => (a.log < b.log ? -1 : a.log > b.log ? 1 : 0));

// The two basic topics, with per-sample hooks: js(s, i) -> {data, stamp?} or
// null to drop; pose stamp offset; log time shift.
function basic(sim, o = {}) {
  const msgs = [];
  sim.forEach((s, i) => {
    const t = ns(s.t);
    const shift = o.logShift ? o.logShift(i) : 0n;
    const h = o.simTime ? BigInt(Math.round(s.t * 1e9)) : t;  // header stamp
    const js = o.js ? o.js(s, i) : jointState(s.t, s, { stamp: h });
    if (js) msgs.push({ topic: "/joint_states", log: t + 2000000n + shift, data: js });
    msgs.push({ topic: "/mocap/pose", log: t + 3000000n + shift, data: poseStamped(h + (o.poseOffsetNs ?? 0n), s.mocap) });
  });
  return msgs;
}

async function main(outDir) {
  await zstd.isLoaded;
  fs.mkdirSync(outDir, { recursive: true });
  const sim = simulate();
  fs.writeFileSync(path.join(outDir, "robot.toml"), `# nominal parameters (the simulated robot's true ones: wheelbase 0.204 m,\n` +
    `# left 0.0842 m, right 0.0838 m)\nwheelbase_m = ${NOMINAL.b}\nwheel_diameter_left_m = ${NOMINAL.dl}\nwheel_diameter_right_m = ${NOMINAL.dr}\n`);
  const write = (name, topics, msgs, compression = "zstd", chunk) => writeMcap(path.join(outDir, name), compression, topics, msgs, chunk);

  // clean: every topic, for the frames and the default picker.
  const all = basic(sim);
  all.push({ topic: "/tf_static", log: ns(0), data: tfMessage(ns(0), [["mocap_marker", "mocap_base", inverse(MARKER)],
    ["base_link", "laser", { x: 0.1, y: 0, th: 0 }]]) });
  sim.forEach((s) => {
    const t = ns(s.t);
    all.push({ topic: "/odom", log: t + 1000000n, data: odometry(t, s.odo) });
    all.push({ topic: "/tf", log: t + 4000000n, data: tfMessage(t, [["odom", "base_link", s.odo]]) });
    all.push({ topic: "/tf", log: t + 5000000n, data: tfMessage(t, [["world", "mocap_marker", compose(s.truth, MARKER)]]) });
  });
  await write("clean.mcap", [JS, MOCAP, ["/odom", "nav_msgs/msg/Odometry"], ["/tf", "tf2_msgs/msg/TFMessage"],
    ["/tf_static", "tf2_msgs/msg/TFMessage"]], sorted(all));

  const mid = 60 + 4 * HZ + 40 + 2 * HZ;  // run 1, half-way along its second leg
  const pos = (s, l, r) => jointState(s.t, s, { position: [s.arm, l, r] });
  const wrap = (a) => a - 2 * Math.PI * Math.floor((a + Math.PI) / (2 * Math.PI));
  await write("reset.mcap", [JS, MOCAP], sorted(basic(sim, { js: (s, i) => i < mid ? jointState(s.t, s)
    : pos(s, s.wl - sim[mid - 1].wl, s.wr - sim[mid - 1].wr) })));
  await write("wrap.mcap", [JS, MOCAP], sorted(basic(sim, { js: (s) => pos(s, wrap(s.wl), wrap(s.wr)) })));
  await write("gap.mcap", [JS, MOCAP], sorted(basic(sim, { js: (s) => (s.t >= 8 && s.t < 14 ? null : jointState(s.t, s)) })));
  await write("jump.mcap", [JS, MOCAP], sorted(basic(sim, { js: (s, i) => (i === mid ? pos(s, s.wl + 6, s.wr) : jointState(s.t, s)) })));
  await write("stuck.mcap", [JS, MOCAP], sorted(basic(sim, { js: (s) => pos(s, s.wl, 0.3) })));
  await write("backwards_joint.mcap", [JS, MOCAP], sorted(basic(sim, { js: (s) => pos(s, s.wl, -s.wr) })));
  await write("same_joint.mcap", [JS, MOCAP], sorted(basic(sim, { js: (s) => pos(s, s.wl, s.wl) })));
  await write("velocity_only.mcap", [JS, MOCAP], sorted(basic(sim, { js: (s) => jointState(s.t, s, { position: [],
    velocity: [0, 1, 1] }) })));
  // /odom restarted from the origin half-way along run 1's second leg.
  const odomReset = basic(sim, { js: () => null });
  sim.forEach((s, i) => {
    const p = i < mid ? s.odo : compose(inverse(sim[mid - 1].odo), s.odo);
    odomReset.push({ topic: "/odom", log: ns(s.t) + 1000000n, data: odometry(ns(s.t), p) });
  });
  await write("odom_reset.mcap", [MOCAP, ["/odom", "nav_msgs/msg/Odometry"]], sorted(odomReset));
  // The robot's odometry with motion-capture noise, published as /mocap/pose.
  const noise = rng(2323);
  await write("odom_as_mocap.mcap", [JS, MOCAP], sorted(basic(sim.map((s) => ({ ...s, mocap: { x: s.odo.x + 2e-4 * noise(),
    y: s.odo.y + 2e-4 * noise(), th: s.odo.th + 5e-4 * noise() } })))));
  await write("clock_offset.mcap", [JS, MOCAP], sorted(basic(sim, { poseOffsetNs: 37000000000n })));
  // Simulation time from 0 in the header stamps; the first joint state sent twice.
  const simTime = basic(sim, { simTime: true });
  simTime.splice(1, 0, { ...simTime[0], log: simTime[0].log + 500000n });
  await write("sim_time_duplicate.mcap", [JS, MOCAP], sorted(simTime));
  // Receive times 200 s back for the second half (not sorted: as stored).
  await write("log_time_back.mcap", [JS, MOCAP], basic(sim, { logShift: (i) => (i >= sim.length / 2 ? -200000000000n : 0n) }));
  // An all-black 640x480 camera in 4 MB zstd chunks (each > 1000x).
  const cam = basic(sim);
  const black = new Uint8Array(640 * 480 * 3);
  sim.forEach((s, i) => {
    if (i % 10) return;
    cam.push({ topic: "/camera/image_raw", log: ns(s.t) + 6000000n, data: encode("sensor_msgs/msg/Image", {
      header: { stamp: stamp(ns(s.t)), frame_id: "camera" }, height: 480, width: 640, encoding: "rgb8", is_bigendian: 0,
      step: 1920, data: black }) });
  });
  await write("black_camera.mcap", [JS, MOCAP, ["/camera/image_raw", "sensor_msgs/msg/Image"]], sorted(cam), "zstd", 4 << 20);
  // 1e6 joint names, three messages.
  const names = new Array(1000000).fill("n"), zeros = new Array(1000000).fill(0);
  await write("million_joints.mcap", [JS], [0, 1, 2].map((k) => ({ topic: "/joint_states", log: ns(k / HZ),
    data: jointState(k / HZ, sim[k], { names, position: zeros }) })), "zstd", 32 << 20);
  // A NaN pose in uncompressed chunks: its record's file offset is exact.
  await write("nan_pose_plain_chunks.mcap", [JS, MOCAP], sorted(basic(sim.slice(0, 80).map((s, i) =>
    (i === 50 ? { ...s, mocap: { ...s.mocap, x: NaN } } : s)))), "none", 4096);
}

await main(process.argv[2] ?? path.resolve(path.dirname(new URL(import.meta.url).pathname), "../robust"));
