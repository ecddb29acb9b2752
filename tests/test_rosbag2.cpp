// rosbag2 import: the containers (MCAP written by @mcap/core with zstd, lz4,
// uncompressed and no chunks; SQLite3 written by ROS 2 itself and by
// Python's sqlite3 in two schema generations), CDR decoding (ROS 2's own
// test messages), and the importer on real robot runs converted to bags
// (tests/data/rosbag2/README.md): the published UMBmark numbers, /odom vs
// joint states, /tf in a rotated world frame, run splitting, bad input.
#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>
#include <sqlite3.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "calibration/calibrate_job.hpp"
#include "core/errors.hpp"
#include "formats/robot_toml.hpp"
#include "ros2/bag.hpp"
#include "ros2/cdr.hpp"
#include "ros2/mcap_reader.hpp"
#include "ros2/messages.hpp"
#include "import/rosbag2_import.hpp"
#include "support/run_cli.hpp"

using namespace umbmark;
using namespace umbmark::io::rosbag2;
using umbmark::testing::Q;
using umbmark::testing::RunCli;
using umbmark::testing::TempDir;
namespace fs = std::filesystem;

namespace {

const fs::path kBags = fs::path(UMBMARK_SOURCE_DIR) / "tests/data/rosbag2";
const fs::path kSamples = kBags / "samples";

RobotParams Robot() { return io::ReadRobotToml((kBags / "robot.toml").string()); }

std::map<std::string, std::uint64_t> Counts(const fs::path& p, std::vector<std::string>* warnings = nullptr) {
  std::vector<std::string> w;
  const Bag bag = Bag::Open(p.string(), w);
  if (warnings) *warnings = w;
  std::map<std::string, std::uint64_t> out;
  for (const auto& t : bag.topics()) out[t.name + " " + t.type] = t.count;
  return out;
}

// Every message payload of one topic, in order.
std::vector<std::vector<std::uint8_t>> Payloads(const fs::path& p, const std::string& topic) {
  std::vector<std::string> w;
  const Bag bag = Bag::Open(p.string(), w);
  std::vector<bool> wanted(bag.topics().size(), false);
  wanted.at(bag.FindTopic(topic).value()) = true;
  std::vector<std::vector<std::uint8_t>> out;
  bag.Read(wanted, [&](const BagMessage& m) { out.emplace_back(m.data, m.data + m.size); });
  return out;
}

Rosbag2ImportOptions Options(const std::string& wheels = "/joint_states", const std::string& gt = "/mocap/pose") {
  Rosbag2ImportOptions o;
  o.kind = ExperimentKind::kSquare;
  o.side_m = 0.75;
  o.wheels_topic = wheels;
  o.ground_truth_topic = gt;
  o.pause_s = 0.0;
  return o;
}

std::string Bytes(const fs::path& p) { return testing::Slurp(p.string()); }
void Write(const fs::path& p, const std::string& s) { std::ofstream(p, std::ios::binary) << s; }

std::uint64_t Le64(const std::string& s, std::size_t at) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(s[at + i]);
  return v;
}

// Offset of the first top-level record with this opcode.
std::size_t FindRecord(const std::string& mcap, unsigned char opcode) {
  std::size_t at = 8;
  while (at + 9 <= mcap.size()) {
    if (static_cast<unsigned char>(mcap[at]) == opcode) return at;
    at += 9 + Le64(mcap, at + 1);
  }
  FAIL("no record with opcode " << int(opcode));
  return 0;
}

}  // namespace

TEST_CASE("rosbag2 samples written by ROS 2: topics and counts as the README states", "[rosbag2][list]") {
  for (const char* b : {"mcap-talker", "sqlite3-talker"}) {
    const auto c = Counts(kSamples / b);
    CHECK(c.size() == 3);
    CHECK(c.at("/topic std_msgs/msg/String") == 10);
    CHECK(c.at("/rosout rcl_interfaces/msg/Log") == 10);
    CHECK(c.at("/parameter_events rcl_interfaces/msg/ParameterEvent") == 0);
  }
  for (const char* b : {"mcap-cdr_test", "sqlite3-cdr_test"}) {
    const auto c = Counts(kSamples / b);
    CHECK(c.at("/test_topic test_msgs/msg/BasicTypes") == 3);
    CHECK(c.at("/array_topic test_msgs/msg/Arrays") == 4);
  }
  for (const char* b : {"mcap-split", "sqlite3-split"}) {
    std::vector<std::string> warnings;
    const auto c = Counts(kSamples / b, &warnings);
    CHECK(c.at("/chatter std_msgs/msg/String") == 1324 + 1324 + 529);
    REQUIRE(warnings.size() == 1);  // no metadata.yaml
    CHECK_THAT(warnings[0], Catch::Contains("name order"));
    // Reading through every file gives the same number of messages.
    CHECK(Payloads(kSamples / b, "/chatter").size() == 3177);
  }
  const auto empty = Counts(kSamples / "sqlite3-empty");
  CHECK(empty.size() == 2);
  for (const auto& [k, n] : empty) CHECK(n == 0);

  const auto r = RunCli("import rosbag2 " + Q(kSamples / "mcap-talker") + " --list");
  CHECK(r.status == 0);
  CHECK_THAT(r.out, Catch::Contains("/topic") && Catch::Contains("std_msgs/msg/String"));
}

TEST_CASE("CDR of ROS 2's own messages: strings, basic types, arrays", "[rosbag2][cdr]") {
  for (const char* b : {"mcap-talker", "sqlite3-talker"}) {
    const auto msgs = Payloads(kSamples / b, "/topic");
    REQUIRE(msgs.size() == 10);
    for (std::size_t i = 0; i < msgs.size(); ++i) {
      CdrReader r(msgs[i].data(), msgs[i].size());
      CHECK(r.String() == "Hello, world! " + std::to_string(i));
      CHECK(r.offset() == r.size());
    }
  }
  for (const char* b : {"mcap-cdr_test", "sqlite3-cdr_test"}) {
    // test_msgs/BasicTypes: bool, byte, char, float32, float64, int8, uint8,
    // int16, uint16, int32, uint32, int64, uint64 (rosbag2 sets int32 = 123).
    for (const auto& m : Payloads(kSamples / b, "/test_topic")) {
      CdrReader r(m.data(), m.size());
      CHECK(r.Read<std::uint8_t>() == 0);
      r.Read<std::uint8_t>();
      r.Read<std::uint8_t>();
      CHECK(r.Read<float>() == 0.0f);
      CHECK(r.Read<double>() == 0.0);
      r.Read<std::int8_t>();
      r.Read<std::uint8_t>();
      r.Read<std::int16_t>();
      r.Read<std::uint16_t>();
      CHECK(r.Read<std::int32_t>() == 123);
      CHECK(r.Read<std::uint32_t>() == 0);
      CHECK(r.Read<std::int64_t>() == 0);
      CHECK(r.Read<std::uint64_t>() == 0);
      CHECK(r.offset() == r.size());  // 4 + 48 bytes: every alignment right
    }
    // test_msgs/Arrays: fixed arrays of 3 of each basic type, then string[3].
    for (const auto& m : Payloads(kSamples / b, "/array_topic")) {
      CdrReader r(m.data(), m.size());
      CHECK(r.Read<std::uint8_t>() == 1);
      CHECK(r.Read<std::uint8_t>() == 0);
      CHECK(r.Read<std::uint8_t>() == 1);
      r.Skip(3, 1);  // byte
      r.Skip(3, 1);  // char
      r.Skip(3, 4);  // float32
      r.Skip(3, 8);  // float64
      r.Skip(3, 1);  // int8
      r.Skip(3, 1);  // uint8
      r.Skip(3, 2);  // int16
      r.Skip(3, 2);  // uint16
      r.Skip(3, 4);  // int32
      r.Skip(3, 4);  // uint32
      r.Skip(3, 8);  // int64
      r.Skip(3, 8);  // uint64
      CHECK(r.offset() == 4 + 144);
      for (int i = 1; i <= 3; ++i) CHECK(r.String() == "Complex Hello" + std::to_string(i));
    }
  }
}

TEST_CASE("CDR: big-endian encapsulation, alignment after the header, bad bytes", "[rosbag2][cdr]") {
  // PoseStamped, big-endian: stamp (sec 7, nanosec 5), frame_id "w", then
  // 7 doubles aligned to 8 after the 4-byte header.
  std::vector<std::uint8_t> be = {0, 0, 0, 0, 0, 0, 0, 7, 0, 0, 0, 5, 0, 0, 0, 2, 'w', 0};
  be.resize(be.size() + 2, 0);  // doubles align at 16 after the header: absolute byte 20
  auto put = [&](double v) {
    std::uint64_t u;
    std::memcpy(&u, &v, 8);
    for (int i = 7; i >= 0; --i) be.push_back(static_cast<std::uint8_t>(u >> (8 * i)));
  };
  for (double v : {1.5, -2.25, 0.0, 0.0, 0.0, std::sin(0.5), std::cos(0.5)}) put(v);
  CdrReader r(be.data(), be.size());
  CHECK(r.big_endian());
  const PoseMsg p = DecodePoseStamped(r);
  CHECK(p.header.stamp_ns == 7000000005LL);
  CHECK(p.header.frame_id == "w");
  CHECK(p.x == 1.5);
  CHECK(p.y == -2.25);
  CHECK_THAT(p.Yaw(), Catch::WithinAbs(1.0, 1e-15));
  CHECK(r.offset() == r.size());

  const std::vector<std::uint8_t> xcdr2 = {0, 7, 0, 0, 1, 0, 0, 0};
  CHECK_THROWS_AS(CdrReader(xcdr2.data(), xcdr2.size()), CdrError);
  std::vector<std::uint8_t> cut(be.begin(), be.end() - 3);
  CdrReader rc(cut.data(), cut.size());
  CHECK_THROWS_AS(DecodePoseStamped(rc), CdrError);
  // A sequence count larger than the message is refused before allocating.
  const std::vector<std::uint8_t> huge = {0, 1, 0, 0, 0xff, 0xff, 0xff, 0x7f};
  CdrReader rh(huge.data(), huge.size());
  CHECK_THROWS_AS(rh.SequenceLength(8), CdrError);
}

TEST_CASE("Converted OptiOdom bags reproduce the published UMBmark numbers", "[rosbag2][published]") {
  std::vector<std::string> bags;
  for (int k = 1; k <= 6; ++k) bags.push_back((kBags / ("square_run" + std::to_string(k) + ".mcap")).string());
  const RobotParams robot = Robot();
  const auto imp = ImportRosbag2(bags, robot, Options());
  REQUIRE(imp.runs.runs.size() == 6);
  // Published row `umbmark,square/230620202042` (data/optiodom-2020-06/published-results.csv).
  CalibrateJobOptions o;
  o.umbmark.estimator = UmbmarkEstimator::kX;
  o.integrator = Integrator::kMidpoint;
  const auto in = InputFromTrajectories(imp.runs, robot, imp.experiment.side_m, Integrator::kMidpoint, "bags");
  const auto r = RunCalibrateJob(in, o);
  CHECK_THAT(r.umbmark.corrected.wheelbase_m, Catch::WithinAbs(0.201458, 1e-6));
  CHECK_THAT(r.umbmark.corrected.wheel_diameter_right_m, Catch::WithinAbs(0.083954, 1e-6));
  CHECK_THAT(r.umbmark.corrected.wheel_diameter_left_m, Catch::WithinAbs(0.084046, 1e-6));
  REQUIRE(r.evaluation);
  CHECK_THAT(r.evaluation->before.max_max_position_error_m, Catch::WithinAbs(0.035057, 1e-6));
  CHECK_THAT(r.evaluation->after.max_max_position_error_m, Catch::WithinAbs(0.022345, 1e-6));
  CHECK_THAT(r.evaluation->after.max_final_position_error_m, Catch::WithinAbs(0.007157, 1e-6));
  const std::vector<std::string> dirs = {"cw", "cw", "cw", "ccw", "ccw", "ccw"};
  for (std::size_t i = 0; i < 6; ++i) CHECK(imp.runs.runs[i].direction == dirs[i]);

  // The same through the command line: import, then calibrate the manifest.
  const fs::path dir = TempDir("rosbag2-pub");
  std::string args = "import rosbag2";
  for (const auto& b : bags) args += " " + Q(b);
  const auto ri = RunCli(args + " --out " + Q(dir) + " --experiment square --side 0.75 --robot " + Q(kBags / "robot.toml") +
                         " --wheels /joint_states --ground-truth /mocap/pose --pause 0");
  REQUIRE(ri.status == 0);
  const auto rc = RunCli("calibrate " + Q(dir / "campaign.toml") + " --estimator x --integrator midpoint --json -");
  REQUIRE(rc.status == 0);
  const auto j = nlohmann::json::parse(rc.out);
  CHECK_THAT(j["parameters"]["wheelbase_m"].get<double>(), Catch::WithinAbs(0.201458, 1e-6));
}

TEST_CASE("/odom inverted with the wheelbase gives the joint states' wheel travel; /tf in a rotated world the same ground truth",
          "[rosbag2][odom]") {
  const std::vector<std::string> bag = {(kBags / "square_run1.mcap").string()};
  const RobotParams robot = Robot();
  const auto js = ImportRosbag2(bag, robot, Options()).runs.runs.at(0);
  auto o = Options("", "/tf");
  o.odometry_topic = "/odom";
  o.ground_truth_frame = "base_link";
  const auto od = ImportRosbag2(bag, robot, o).runs.runs.at(0);
  REQUIRE(od.size() == js.size());
  double worst_wheel = 0, worst_gt = 0;
  for (std::size_t i = 0; i < js.size(); ++i) {
    worst_wheel = std::max({worst_wheel, std::abs(od.dist_left_m[i] - js.dist_left_m[i]),
                            std::abs(od.dist_right_m[i] - js.dist_right_m[i])});
    worst_gt = std::max({worst_gt, std::abs(od.gt_x_m[i] - js.gt_x_m[i]), std::abs(od.gt_y_m[i] - js.gt_y_m[i]),
                         std::abs(od.gt_theta_rad[i] - js.gt_theta_rad[i])});
  }
  CHECK(worst_wheel < 1e-9);  // 3.6 m of travel, rounding only
  CHECK(worst_gt < 1e-9);
  CHECK(od.direction == js.direction);
  // The midpoint inversion of an arc-integrated /odom is off by O(ds dtheta^2).
  o.integrator = Integrator::kMidpoint;
  const auto mid = ImportRosbag2(bag, robot, o).runs.runs.at(0);
  CHECK(std::abs(mid.dist_left_m.back() - js.dist_left_m.back()) > 1e-9);
  CHECK(std::abs(mid.dist_left_m.back() - js.dist_left_m.back()) < 1e-3);
}

TEST_CASE("A continuous recording splits at pauses into the runs with their cw/ccw labels", "[rosbag2][split]") {
  const RobotParams robot = Robot();
  auto o = Options();
  o.pause_s = 2.0;
  const auto cont = ImportRosbag2({(kBags / "square_continuous.mcap").string()}, robot, o);
  REQUIRE(cont.runs.runs.size() == 3);
  // The recording holds OptiOdom runs 1, 4, 2 with 3 s standing between.
  const std::vector<std::pair<int, std::string>> src = {{1, "cw"}, {4, "ccw"}, {2, "cw"}};
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& run = cont.runs.runs[i];
    CHECK(run.run == std::to_string(i + 1));
    CHECK(run.direction == src[i].second);
    const auto one = ImportRosbag2({(kBags / ("square_run" + std::to_string(src[i].first) + ".mcap")).string()}, robot,
                                   Options()).runs.runs.at(0);
    CHECK_THAT(run.dist_left_m.back(), Catch::WithinAbs(one.dist_left_m.back(), 1e-12));
    CHECK_THAT(run.dist_right_m.back(), Catch::WithinAbs(one.dist_right_m.back(), 1e-12));
    // A run starts at the pause's last sample: the wheels move right after it.
    CHECK(run.dist_left_m[1] + run.dist_right_m[1] != 0.0);
  }
  o.pause_s = 0.0;
  o.kind = ExperimentKind::kFree;
  const auto whole = ImportRosbag2({(kBags / "square_continuous.mcap").string()}, robot, o);
  CHECK(whole.runs.runs.size() == 1);
  CHECK(whole.runs.runs[0].direction == "free");
}

TEST_CASE("SQLite3 bags (Humble folder, Jazzy schema) and MCAP without chunks read the same messages", "[rosbag2][sqlite]") {
  const RobotParams robot = Robot();
  auto o = Options();
  o.kind = ExperimentKind::kFree;
  const auto ref = ImportRosbag2({(kBags / "run1_head_unchunked.mcap").string()}, robot, o).runs.runs.at(0);
  REQUIRE(ref.size() == 200);
  for (const char* b : {"humble", "jazzy.db3", "run1_head_plain_chunks.mcap"}) {
    const auto run = ImportRosbag2({(kBags / b).string()}, robot, o).runs.runs.at(0);
    REQUIRE(run.size() == ref.size());
    for (std::size_t i = 0; i < ref.size(); ++i) {
      CHECK(run.t_s[i] == ref.t_s[i]);
      CHECK(run.dist_left_m[i] == ref.dist_left_m[i]);
      CHECK(run.gt_theta_rad[i] == ref.gt_theta_rad[i]);
    }
  }
}

TEST_CASE("Bad recordings: exit 1 naming the file and the byte offset or topic", "[rosbag2][bad]") {
  const fs::path dir = TempDir("rosbag2-bad");
  const std::string robot = " --robot " + Q(kBags / "robot.toml");
  auto import = [&](const fs::path& bag, const std::string& extra = " --wheels /joint_states --ground-truth /mocap/pose") {
    return RunCli("import rosbag2 " + Q(bag) + " --out " + Q(dir / "out") + " --experiment free" + robot + extra);
  };
  auto expect = [&](const testing::CliResult& r, const fs::path& file, const std::string& what) {
    CHECK(r.status == 1);
    CHECK_THAT(r.err, Catch::Contains(file.string()) && Catch::Contains(what));
  };
  const std::string good = Bytes(kBags / "square_run3.mcap");
  const std::size_t chunk = FindRecord(good, 0x06);

  const fs::path mid_record = dir / "mid_record.mcap";
  Write(mid_record, good.substr(0, 8 + 4));
  expect(import(mid_record), mid_record, "byte 8: file ends inside a record header");
  const fs::path mid_chunk = dir / "mid_chunk.mcap";
  Write(mid_chunk, good.substr(0, chunk + 500));
  expect(import(mid_chunk), mid_chunk, "byte " + std::to_string(chunk) + ": Chunk record");
  const fs::path no_footer = dir / "no_footer.mcap";
  Write(no_footer, good.substr(0, FindRecord(good, 0x0F)));
  expect(import(no_footer), no_footer, "without a Footer");

  std::string bad = good;
  bad[chunk + 200] = static_cast<char>(bad[chunk + 200] ^ 0x5a);  // inside the zstd frame
  const fs::path zstd_bad = dir / "corrupt_zstd.mcap";
  Write(zstd_bad, bad);
  const auto rz = import(zstd_bad);
  CHECK(rz.status == 1);
  CHECK_THAT(rz.err, Catch::Contains(zstd_bad.string() + ": byte " + std::to_string(chunk)));
  CHECK_THAT(rz.err, Catch::Contains("zstd") || Catch::Contains("CRC"));

  std::string plain = Bytes(kBags / "run1_head_plain_chunks.mcap");
  const std::size_t pc = FindRecord(plain, 0x06);
  plain[plain.size() > pc + 300 ? pc + 300 : pc + 80] ^= 0x01;  // one bit of a message inside an uncompressed chunk
  const fs::path crc_bad = dir / "crc.mcap";
  Write(crc_bad, plain);
  expect(import(crc_bad), crc_bad, "chunk CRC mismatch");

  std::string magic = good;
  magic[1] = 'X';
  const fs::path magic_bad = dir / "magic.mcap";
  Write(magic_bad, magic);
  expect(import(magic_bad), magic_bad, "not an MCAP file");
  // A rejected file is closed: 300 rejections leave the process's open
  // descriptors as they were (the constructor used to leak its FILE).
  auto open_fds = [] {
    std::size_t n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator("/proc/self/fd")) ++n;
    return n;
  };
  const std::size_t fds_before = open_fds();
  for (int i = 0; i < 300; ++i) CHECK_THROWS_AS(McapReader(magic_bad.string()), InputError);
  CHECK(open_fds() == fds_before);

  // SQLite3: a database that is not a rosbag2, and a locked one.
  const fs::path other = dir / "other.db3";
  sqlite3* db = nullptr;
  REQUIRE(sqlite3_open(other.string().c_str(), &db) == SQLITE_OK);
  REQUIRE(sqlite3_exec(db, "CREATE TABLE foo(x INTEGER)", nullptr, nullptr, nullptr) == SQLITE_OK);
  sqlite3_close(db);
  expect(import(other), other, "not a rosbag2 database");
  const fs::path text = dir / "text.db3";
  Write(text, std::string(4096, 'x'));
  expect(import(text), text, "not an SQLite3 database");
  const fs::path locked = dir / "locked.db3";
  fs::copy_file(kBags / "jazzy.db3", locked);
  REQUIRE(sqlite3_open(locked.string().c_str(), &db) == SQLITE_OK);
  REQUIRE(sqlite3_exec(db, "BEGIN EXCLUSIVE", nullptr, nullptr, nullptr) == SQLITE_OK);
  expect(import(locked), locked, "locked");
  sqlite3_exec(db, "ROLLBACK", nullptr, nullptr, nullptr);
  sqlite3_close(db);

  // Topics, joints and types: the message lists what is there.
  const fs::path run1 = kBags / "square_run1.mcap";
  const auto missing = import(run1, " --wheels /wheels");
  expect(missing, run1, "--wheels topic /wheels is not in the recording");
  CHECK_THAT(missing.err, Catch::Contains("/joint_states  sensor_msgs/msg/JointState  (1814 messages)"));
  const auto joint = import(run1, " --wheels /joint_states --left-joint wheel_l");
  expect(joint, run1, "joint 'wheel_l' is not in the message; its joints are: left_wheel_joint, right_wheel_joint, caster_joint");
  expect(import(run1, " --wheels /joint_states --ground-truth /joint_states"), run1,
         "has type sensor_msgs/msg/JointState, which holds no pose");
  expect(import(run1, " --wheels /odom"), run1, "use --odometry");
  expect(import(run1, " --wheels /joint_states --ground-truth /tf --ground-truth-frame base"), run1,
         "frames seen: camera_link (parent world), base_link (parent world)");
  // One header stamp 0.2 s back: the joint states repeat an earlier
  // message exactly there (the robot stands), which is harmless; the pose
  // differs, which is not.
  expect(import(kBags / "bad_stamps.mcap"), kBags / "bad_stamps.mcap", "topic /mocap/pose");
  CHECK_THAT(import(kBags / "bad_stamps.mcap").err, Catch::Contains("does not increase"));
  expect(import(kBags / "nan_pose.mcap"), kBags / "nan_pose.mcap", "topic /mocap/pose");
  CHECK_THAT(import(kBags / "nan_pose.mcap").err, Catch::Contains("not finite"));
  // Nothing was written by any of these.
  CHECK_FALSE(fs::exists(dir / "out" / "runs.csv"));
}

TEST_CASE("metadata.yaml: file order, flow lists, rosbag2-compressed bags refused", "[rosbag2][metadata]") {
  const fs::path dir = TempDir("rosbag2-meta");
  Write(dir / "metadata.yaml",
        "rosbag2_bagfile_information:\n  version: 5\n  relative_file_paths:\n  - b_1.mcap\n  - 'a_0.mcap'\n  storage_identifier: mcap\n");
  CHECK(ReadMetadataFileList((dir / "metadata.yaml").string()) == std::vector<std::string>{"b_1.mcap", "a_0.mcap"});
  Write(dir / "flow.yaml", "rosbag2_bagfile_information:\n  relative_file_paths: [x_0.db3, x_1.db3]\n");
  CHECK(ReadMetadataFileList((dir / "flow.yaml").string()) == std::vector<std::string>{"x_0.db3", "x_1.db3"});
  Write(dir / "zstd.yaml",
        "rosbag2_bagfile_information:\n  compression_format: zstd\n  compression_mode: FILE\n  relative_file_paths:\n"
        "  - talker_0.mcap.zstd\n");
  CHECK_THROWS_WITH(ReadMetadataFileList((dir / "zstd.yaml").string()), Catch::Contains("ros2 bag decompress"));
  Write(dir / "none.yaml", "rosbag2_bagfile_information:\n  version: 5\n");
  CHECK_THROWS_AS(ReadMetadataFileList((dir / "none.yaml").string()), InputError);
}
