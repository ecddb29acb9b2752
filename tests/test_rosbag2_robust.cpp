// rosbag2 import on recordings as real robots make them (issue 23): wheel
// encoders that wrap, reset, jump, stick, repeat one joint or leave gaps;
// /tf trees with an odom frame and /tf_static marker offsets; clocks that
// differ, repeated stamps, receive times that go back; zstd chunks past
// 1000x, generated SQLite data, a million joint names, 200,000 topics.
// Fixtures: tests/data/rosbag2/robust/ (written by generator/gen_robust.mjs
// with @mcap/core and @foxglove/rosmsg2-serialization from a simulated
// robot driving a 1 m square by its nominal odometry); SQLite databases are
// written here by SQLite itself. Each case: the right result (checked
// against the clean recording or a closed form) or exit 1 naming the topic,
// joint, frame or stamp.
#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>
#include <sqlite3.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>

#include "core/errors.hpp"
#include "formats/robot_toml.hpp"
#include "ros2/mcap_reader.hpp"
#include "import/rosbag2_import.hpp"
#include "support/run_cli.hpp"

using namespace umbmark;
using namespace umbmark::io::rosbag2;
using umbmark::testing::Q;
using umbmark::testing::RunCli;
using umbmark::testing::TempDir;
namespace fs = std::filesystem;

namespace {

const fs::path kDir = fs::path(UMBMARK_SOURCE_DIR) / "tests/data/rosbag2/robust";

RobotParams Robot() { return io::ReadRobotToml((kDir / "robot.toml").string()); }

Rosbag2ImportOptions Options(const std::string& gt = "/mocap/pose") {
  Rosbag2ImportOptions o;
  o.kind = ExperimentKind::kSquare;
  o.side_m = 1.0;
  o.wheels_topic = "/joint_states";
  o.ground_truth_topic = gt;
  return o;
}

Rosbag2Import Import(const std::string& name, const Rosbag2ImportOptions& o = Options()) {
  return ImportRosbag2({(kDir / name).string()}, Robot(), o);
}

std::string ImportError(const std::string& name, const Rosbag2ImportOptions& o = Options()) {
  try {
    Import(name, o);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

bool AnyContains(const std::vector<std::string>& v, const std::string& what) {
  for (const auto& s : v)
    if (s.find(what) != std::string::npos) return true;
  return false;
}

// Largest difference of the wheel travel between two runs of equal length.
double TravelDiff(const TrajectoryRun& a, const TrajectoryRun& b) {
  REQUIRE(a.size() == b.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i)
    worst = std::max({worst, std::abs(a.dist_left_m[i] - b.dist_left_m[i]), std::abs(a.dist_right_m[i] - b.dist_right_m[i])});
  return worst;
}
double GtDiff(const TrajectoryRun& a, const TrajectoryRun& b, bool heading = true) {
  REQUIRE(a.size() == b.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i)
    worst = std::max({worst, std::hypot(a.gt_x_m[i] - b.gt_x_m[i], a.gt_y_m[i] - b.gt_y_m[i]),
                      heading ? std::abs(a.gt_theta_rad[i] - b.gt_theta_rad[i]) : 0.0});
  return worst;
}

std::string CliImport(const std::string& name, const std::string& extra, const fs::path& out, int expect_status) {
  const auto r = RunCli("import rosbag2 " + Q(kDir / name) + " --out " + Q(out) + " --experiment square --side 1 --robot " +
                        Q(kDir / "robot.toml") + " " + extra);
  CHECK(r.status == expect_status);
  return r.status == 0 ? r.out : r.err;
}

}  // namespace

TEST_CASE("Clean simulated recording: travel in closed form, joints picked past left_right_arm", "[rosbag2][robust]") {
  const auto clean = Import("clean.mcap");
  REQUIRE(clean.runs.runs.size() == 2);
  // Nominal odometry drives 4 legs of 1 m and turns 4 x 90 deg in place on
  // the nominal 0.2 m wheelbase: each wheel travels 4 m +- 4 (0.1 pi/2) m.
  const double turn = 4 * 0.1 * kPi / 2;
  CHECK_THAT(clean.runs.runs[0].dist_left_m.back(), Catch::WithinAbs(4 + turn, 1e-9));
  CHECK_THAT(clean.runs.runs[0].dist_right_m.back(), Catch::WithinAbs(4 - turn, 1e-9));
  CHECK_THAT(clean.runs.runs[1].dist_left_m.back(), Catch::WithinAbs(4 - turn, 1e-9));
  CHECK(clean.runs.runs[0].direction == "cw");
  CHECK(clean.runs.runs[1].direction == "ccw");
  // The default picker skips left_right_arm (both sides in its name).
  CHECK(clean.recordings.at(0).left_joint == "left_wheel_joint");
  CHECK(clean.recordings.at(0).right_joint == "right_wheel_joint");
  // --odometry /odom (the robot's own, nominal parameters) gives the same travel.
  auto o = Options();
  o.wheels_topic.clear();
  o.odometry_topic = "/odom";
  const auto od = Import("clean.mcap", o);
  for (std::size_t r = 0; r < 2; ++r) CHECK(TravelDiff(od.runs.runs[r], clean.runs.runs[r]) < 1e-9);
}

TEST_CASE("Wheel encoders: wraps unwrapped, a reset stitched, a gap drops its run, all with warnings", "[rosbag2][robust]") {
  const auto clean = Import("clean.mcap");
  const auto wrap = Import("wrap.mcap");
  REQUIRE(wrap.runs.runs.size() == 2);
  for (std::size_t r = 0; r < 2; ++r) CHECK(TravelDiff(wrap.runs.runs[r], clean.runs.runs[r]) < 1e-9);
  CHECK(AnyContains(wrap.warnings, "joint left_wheel_joint: positions are wrapped into one revolution"));

  // Both joints reset to 0 half-way along run 1's second leg (constant
  // speed there, so the stitched step is exact).
  const auto reset = Import("reset.mcap");
  REQUIRE(reset.runs.runs.size() == 2);
  for (std::size_t r = 0; r < 2; ++r) CHECK(TravelDiff(reset.runs.runs[r], clean.runs.runs[r]) < 1e-9);
  CHECK(AnyContains(reset.warnings, "joint right_wheel_joint: position resets to 0 1 time(s) (first at stamp 1700000011.000000000"));

  // The controller's /odom restarted from the origin at the same place.
  auto od = Options();
  od.wheels_topic.clear();
  od.odometry_topic = "/odom";
  const auto odom_reset = Import("odom_reset.mcap", od);
  REQUIRE(odom_reset.runs.runs.size() == 2);
  for (std::size_t r = 0; r < 2; ++r) CHECK(TravelDiff(odom_reset.runs.runs[r], clean.runs.runs[r]) < 1e-9);
  CHECK(AnyContains(odom_reset.warnings, "topic /odom, left wheel: the odometry pose resets to the origin 1 time(s)"));

  // 6 s without /joint_states while run 1 drives: run 1 is dropped, run 2 kept.
  const auto gap = Import("gap.mcap");
  REQUIRE(gap.runs.runs.size() == 1);
  CHECK(gap.runs.runs[0].run == "1");
  CHECK(gap.runs.runs[0].direction == "ccw");
  CHECK(TravelDiff(gap.runs.runs[0], clean.runs.runs[1]) < 1e-12);
  CHECK(gap.recordings.at(0).runs_dropped == 1);
  CHECK(AnyContains(gap.warnings, "topic /joint_states has no message for 6.05 s"));

  // The same through the command line: warnings in the summary and in JSON.
  const fs::path dir = TempDir("rosbag2-robust-gap");
  const auto out = CliImport("gap.mcap", "--wheels /joint_states --ground-truth /mocap/pose --json -", dir / "o", 0);
  const auto j = nlohmann::json::parse(out);
  CHECK(j["recordings"][0]["runs_dropped"] == 1);
  bool found = false;
  for (const auto& w : j["warnings"]) found = found || w.get<std::string>().find("so that run is dropped") != std::string::npos;
  CHECK(found);
}

TEST_CASE("Wheel encoders: a jump, a stuck joint, one joint twice, velocity only are refused in ROS terms",
          "[rosbag2][robust]") {
  const std::string jump = ImportError("jump.mcap");
  CHECK_THAT(jump, Catch::Contains("topic /joint_states, joint left_wheel_joint: position jumps by 6.") &&
                       Catch::Contains("at stamp 1700000011.000000000 (message 221)"));
  CHECK_THAT(ImportError("stuck.mcap"), Catch::Contains("joint right_wheel_joint travels 0 m in all"));
  CHECK_THAT(ImportError("backwards_joint.mcap"), Catch::Contains("run 1: joint right_wheel_joint travels -3.372 m") &&
                                                      Catch::Contains("--odometry"));
  CHECK_THAT(ImportError("same_joint.mcap"),
             Catch::Contains("joints left_wheel_joint and right_wheel_joint report the same position in all 1140 messages"));
  CHECK_THAT(ImportError("velocity_only.mcap"), Catch::Contains("velocity[] but no position[]") &&
                                                    Catch::Contains("--odometry TOPIC"));
  auto o = Options();
  o.left_joint = o.right_joint = "left_wheel_joint";
  CHECK_THROWS_AS(Import("clean.mcap", o), InvalidOptions);
  // Swapped joints: said with the flags to use, not CSV columns.
  o.left_joint = "right_wheel_joint";
  o.right_joint = "left_wheel_joint";
  CHECK_THAT(ImportError("clean.mcap", o), Catch::Contains("in 2 of 2 runs the wheels turn the other way") &&
                                               Catch::Contains("--left-joint left_wheel_joint --right-joint right_wheel_joint"));
  // Nothing is written when refused (exit 1).
  const fs::path dir = TempDir("rosbag2-robust-refuse");
  CHECK_THAT(CliImport("stuck.mcap", "--wheels /joint_states", dir / "o", 1), Catch::Contains("stuck"));
  CHECK_FALSE(fs::exists(dir / "o" / "runs.csv"));
}

TEST_CASE("/tf as a tree: odom chains refused, /tf_static offsets composed, --list shows every frame's parent",
          "[rosbag2][robust][tf]") {
  const auto mocap = Import("clean.mcap");
  auto o = Options("/tf");
  o.ground_truth_frame = "base_link";
  CHECK_THAT(ImportError("clean.mcap", o), Catch::Contains("the frame's chain odom -> base_link runs through the odometry frame 'odom'"));
  // The axle frame, fixed to the mocap marker by /tf_static: the true axle
  // pose, as /mocap/pose has it (0.2 mm / 0.5 mrad noise there).
  o.ground_truth_frame = "mocap_base";
  const auto axle = Import("clean.mcap", o);
  REQUIRE(axle.runs.runs.size() == 2);
  for (std::size_t r = 0; r < 2; ++r) CHECK(GtDiff(axle.runs.runs[r], mocap.runs.runs[r]) < 3e-3);
  // The marker itself (8 cm ahead, 3 cm left) swings around the axle: ~12 cm off after a quarter turn.
  o.ground_truth_frame = "mocap_marker";
  const auto marker = Import("clean.mcap", o);
  CHECK(GtDiff(marker.runs.runs[0], mocap.runs.runs[0], false) > 0.05);
  // The odometry again, with motion-capture noise added: no drift beyond its noise.
  CHECK_THAT(ImportError("odom_as_mocap.mcap"), Catch::Contains("follows the wheel odometry"));
  // Ground truth that is the odometry itself.
  CHECK_THAT(ImportError("clean.mcap", Options("/odom")), Catch::Contains("follows the wheel odometry") &&
                                                            Catch::Contains("--ground-truth /odom"));

  const auto r = RunCli("import rosbag2 " + Q(kDir / "clean.mcap") + " --list --json -");
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.out);
  std::map<std::string, nlohmann::json> frames;
  for (const auto& t : j["bags"][0]["topics"])
    for (const auto& f : t["frames"]) frames[f["frame"].get<std::string>()] = f;
  REQUIRE(frames.size() == 4);
  CHECK(frames["base_link"]["parent"] == "odom");
  CHECK(frames["base_link"]["through_odometry"] == "odom");
  CHECK_THAT(frames["base_link"]["rate_hz"].get<double>(), Catch::WithinAbs(20.0, 1e-9));
  CHECK(frames["mocap_marker"]["parent"] == "world");
  CHECK(frames["mocap_marker"]["through_odometry"] == "");
  CHECK(frames["mocap_base"]["parent"] == "mocap_marker");
  CHECK(frames["mocap_base"]["static"] == true);
  const auto text = RunCli("import rosbag2 " + Q(kDir / "clean.mcap") + " --list");
  CHECK_THAT(text.out, Catch::Contains("frame mocap_marker") && Catch::Contains("parent world"));
}

TEST_CASE("Clocks: a 37 s offset named, --time per stream, repeated stamps taken, receive times going back refused",
          "[rosbag2][robust][time]") {
  const auto clean = Import("clean.mcap");
  const std::string off = ImportError("clock_offset.mcap");
  CHECK_THAT(off, Catch::Contains("clocks 37.0 s apart") && Catch::Contains("--time header,log"));
  // --list shows it too: header stamp minus receive time per topic.
  const auto listed = RunCli("import rosbag2 " + Q(kDir / "clock_offset.mcap") + " --list --json -");
  REQUIRE(listed.status == 0);
  const auto lj = nlohmann::json::parse(listed.out);
  CHECK_THAT(lj["bags"][0]["topics"][0]["header_minus_receive_s"].get<double>(), Catch::WithinAbs(-0.002, 1e-9));
  CHECK_THAT(lj["bags"][0]["topics"][1]["header_minus_receive_s"].get<double>(), Catch::WithinAbs(36.997, 1e-9));
  auto o = Options();
  o.ground_truth_time = StampSource::kLog;  // --time header,log
  const auto fixed = Import("clock_offset.mcap", o);
  REQUIRE(fixed.runs.runs.size() == 2);
  // Receive times are 3 ms after the pose: 0.75 mm at 0.25 m/s, plus noise.
  for (std::size_t r = 0; r < 2; ++r) {
    CHECK(TravelDiff(fixed.runs.runs[r], clean.runs.runs[r]) < 1e-12);
    CHECK(GtDiff(fixed.runs.runs[r], clean.runs.runs[r]) < 5e-3);
  }
  const fs::path dir = TempDir("rosbag2-robust-time");
  CliImport("clock_offset.mcap", "--wheels /joint_states --ground-truth /mocap/pose --time header,log", dir / "a", 0);
  CliImport("clean.mcap", "--wheels /joint_states --ground-truth /mocap/pose --time log", dir / "b", 0);

  // Simulation time from 0 with the first joint state sent twice.
  const auto sim = Import("sim_time_duplicate.mcap");
  REQUIRE(sim.runs.runs.size() == 2);
  for (std::size_t r = 0; r < 2; ++r) CHECK(TravelDiff(sim.runs.runs[r], clean.runs.runs[r]) < 1e-12);
  CHECK(AnyContains(sim.warnings, "1 message(s) repeat the previous message's stamp and values"));

  // Receive times 200 s back half-way: header stamps are fine, receive times refused with a hint.
  CHECK(Import("log_time_back.mcap").runs.runs.size() == 2);
  o = Options();
  o.time = StampSource::kLog;
  CHECK_THAT(ImportError("log_time_back.mcap", o), Catch::Contains("receive stamp") && Catch::Contains("try --time header"));
}

TEST_CASE("Readers: zstd chunks past 1000x, message byte offsets inside chunks, long lists trimmed", "[rosbag2][robust][readers]") {
  // The black camera's chunks expand far beyond 1000x: read the first one's header.
  const std::string bytes = testing::Slurp((kDir / "black_camera.mcap").string());
  std::size_t at = 8;
  while (static_cast<unsigned char>(bytes[at]) != 0x06) {
    std::uint64_t len = 0;
    std::memcpy(&len, bytes.data() + at + 1, 8);
    at += 9 + len;
  }
  std::uint64_t chunk_len = 0, uncompressed = 0;
  std::memcpy(&chunk_len, bytes.data() + at + 1, 8);
  std::memcpy(&uncompressed, bytes.data() + at + 9 + 16, 8);
  CHECK(static_cast<double>(uncompressed) / static_cast<double>(chunk_len) > 1000.0);
  const auto cam = Import("black_camera.mcap");
  CHECK(TravelDiff(cam.runs.runs.at(0), Import("clean.mcap").runs.runs.at(0)) < 1e-12);
  CHECK(RunCli("import rosbag2 " + Q(kDir / "black_camera.mcap") + " --list").status == 0);

  // A NaN pose in an uncompressed chunk: the byte offset is its Message record's.
  const std::string nan = ImportError("nan_pose_plain_chunks.mcap");
  std::smatch m;
  REQUIRE(std::regex_search(nan, m, std::regex("message 51 \\(record at byte ([0-9]+)\\)")));
  const std::string plain = testing::Slurp((kDir / "nan_pose_plain_chunks.mcap").string());
  const std::size_t rec = std::stoul(m[1]);
  REQUIRE(rec + 9 + 22 + 36 <= plain.size());
  CHECK(plain[rec] == 0x05);
  double x = 0;
  // CDR header 4, stamp 8, frame_id length 4 + "world\0" 6, padding to 8 (counted after the CDR header): 28.
  std::memcpy(&x, plain.data() + rec + 9 + 22 + 28, 8);
  CHECK(std::isnan(x));
  // In a zstd chunk: the offset within the decompressed chunk, and the chunk's.
  CHECK_THAT(ImportError("velocity_only.mcap"), Catch::Contains("message 1 (record at byte ") &&
                                                    Catch::Contains("of the decompressed chunk at byte "));

  // A million joint names: one short line.
  const std::string many = ImportError("million_joints.mcap", Options(""));
  CHECK_THAT(many, Catch::Contains("... and 999980 more"));
  CHECK(many.size() < 1000);
  const auto list = RunCli("import rosbag2 " + Q(kDir / "million_joints.mcap") + " --list");
  CHECK(list.status == 0);
  CHECK(list.out.size() < 2000);
}

TEST_CASE("SQLite: 200,000 topics listed trimmed; a generated zeroblob data column refused in bounded memory",
          "[rosbag2][robust][sqlite]") {
  const fs::path dir = TempDir("rosbag2-robust-sqlite");
  auto create = [&](const fs::path& p, const char* messages_table) {
    sqlite3* db = nullptr;
    REQUIRE(sqlite3_open(p.string().c_str(), &db) == SQLITE_OK);
    REQUIRE(sqlite3_exec(db, "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT, type TEXT, serialization_format TEXT, "
                             "offered_qos_profiles TEXT)", nullptr, nullptr, nullptr) == SQLITE_OK);
    REQUIRE(sqlite3_exec(db, messages_table, nullptr, nullptr, nullptr) == SQLITE_OK);
    return db;
  };
  // 200,000 camera topics and one JointState topic.
  const fs::path wide = dir / "wide.db3";
  sqlite3* db = create(wide, "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER, timestamp INTEGER, data BLOB)");
  REQUIRE(sqlite3_exec(db, "BEGIN; WITH RECURSIVE n(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM n WHERE i < 200000) "
                           "INSERT INTO topics SELECT i, '/camera_' || i || '/image_raw', 'sensor_msgs/msg/Image', 'cdr', '' FROM n; "
                           "INSERT INTO topics VALUES (200001, '/joint_states', 'sensor_msgs/msg/JointState', 'cdr', ''); COMMIT",
                       nullptr, nullptr, nullptr) == SQLITE_OK);
  sqlite3_close(db);
  const auto list = RunCli("import rosbag2 " + Q(wide) + " --list");
  CHECK(list.status == 0);
  CHECK_THAT(list.out, Catch::Contains("/joint_states") && Catch::Contains("... and 199960 more topics not listed"));
  CHECK(std::count(list.out.begin(), list.out.end(), '\n') < 60);
  const auto missing = RunCli("import rosbag2 " + Q(wide) + " --out " + Q(dir / "o") +
                              " --experiment free --wheelbase 0.2 --diameter-left 0.08 --diameter-right 0.08 --wheels /wheels");
  CHECK(missing.status == 1);
  CHECK_THAT(missing.err, Catch::Contains("/joint_states") && Catch::Contains("... and 199961 more topics"));
  CHECK(missing.err.size() < 5000);

  // A 12 KB database whose data column is generated: 7 x 500 MB of zeros.
  const fs::path zero = dir / "zeroblob.db3";
  db = create(zero, "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER, timestamp INTEGER, "
                    "data BLOB GENERATED ALWAYS AS (zeroblob(500000000)) VIRTUAL)");
  REQUIRE(sqlite3_exec(db, "INSERT INTO topics VALUES (1, '/joint_states', 'sensor_msgs/msg/JointState', 'cdr', ''); "
                           "WITH RECURSIVE n(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM n WHERE i < 7) "
                           "INSERT INTO messages(id, topic_id, timestamp) SELECT i, 1, i FROM n",
                       nullptr, nullptr, nullptr) == SQLITE_OK);
  sqlite3_close(db);
  CHECK(fs::file_size(zero) < 20000);
  const auto r = RunCli("import rosbag2 " + Q(zero) + " --out " + Q(dir / "z") +
                        " --experiment free --wheelbase 0.2 --diameter-left 0.08 --diameter-right 0.08 --wheels /joint_states");
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::Contains("zeroblob.db3") && Catch::Contains("data column is generated"));
}
