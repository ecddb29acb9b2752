// `umbmark calibrate-lidar` end to end on recordings written by independent
// writers (tests/data/rosbag2/lidar/, generator/drive_gen.mjs: MCAP by
// @mcap/core, CDR by @foxglove/rosmsg2-serialization; a robot with known
// wheels, lidar mount and scan clock drives 100 s of ordinary teleop motion
// in a ray-cast room; the truth is in lidar/README-truth.json), --odometry
// and --distance-m on a drive with the controller's /odom and a lidar whose
// ranges read 1 % long, and bad input.
#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "support/run_cli.hpp"

using umbmark::testing::Q;
using umbmark::testing::RunCli;
using umbmark::testing::Slurp;
using umbmark::testing::TempDir;
using Catch::Matchers::Contains;

namespace {

const std::filesystem::path kLidar = std::filesystem::path(UMBMARK_SOURCE_DIR) / "tests/data/rosbag2/lidar";

// The truth lies within the reported 95 % interval widened to 99.9 % (a
// factor 3.29 / 1.96), and within an absolute bound from the issue's
// targets for a 5-minute drive, relaxed for this 100 s one.
void CheckWithin(const nlohmann::json& j, const char* key, double truth, double bound) {
  INFO(key);
  const double v = j.at(key).get<double>();
  CHECK(std::abs(v - truth) <= bound);
}

void CheckInterval(const nlohmann::json& ci, double value, double truth) {
  const double lo = ci.at(0).get<double>(), hi = ci.at(1).get<double>();
  CHECK(lo <= value);
  CHECK(value <= hi);
  const double half = 0.5 * (hi - lo) * 3.29 / 1.96;
  CHECK(std::abs(truth - value) <= half);
}

std::string Decimal(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6f", v);
  return buf;
}

}  // namespace

TEST_CASE("calibrate-lidar: an upside-down lidar, a late scan clock and a gyro from a bag") {
  const auto dir = TempDir("calibrate-lidar");
  const auto r = RunCli("calibrate-lidar " + Q(kLidar / "drive_upside.mcap") + " --scan /scan --wheels /joint_states --imu /imu --robot " +
                        Q(kLidar / "robot.toml") + " --json " + Q(dir / "out.json") + " --ros2 " + Q(dir / "diff_drive.yaml"));
  INFO(r.out << r.err);
  REQUIRE(r.status == 0);
  const auto truth = nlohmann::json::parse(Slurp((kLidar / "README-truth.json").string()))["drive_upside.mcap"];
  const auto j = nlohmann::json::parse(Slurp((dir / "out.json").string()));
  const auto& p = j["parameters"];
  CheckWithin(p, "wheelbase_m", truth["wheelbase_m"], 0.005 * 0.2856);
  CheckWithin(p, "wheel_diameter_left_m", truth["wheel_diameter_left_m"], 0.003 * 0.066);
  CheckWithin(p, "wheel_diameter_right_m", truth["wheel_diameter_right_m"], 0.003 * 0.066);
  const auto& m = j["lidar_mount"];
  CHECK(m["upside_down"] == true);
  CheckWithin(m, "x_m", truth["mount"][0], 0.01);
  CheckWithin(m, "y_m", truth["mount"][1], 0.01);
  CheckWithin(m, "yaw_rad", truth["mount"][2], 0.005);
  CheckInterval(m["x_m_ci95"], m["x_m"], truth["mount"][0]);
  CheckInterval(m["y_m_ci95"], m["y_m"], truth["mount"][1]);
  CheckInterval(m["yaw_rad_ci95"], m["yaw_rad"], truth["mount"][2]);
  CheckWithin(j, "scan_time_offset_s", truth["scan_time_offset_s"], 0.01);
  CheckInterval(j["scan_time_offset_s_ci95"], j["scan_time_offset_s"], truth["scan_time_offset_s"]);
  CheckWithin(j, "gyro_scale", truth["gyro_scale"], 0.006);
  CheckWithin(j, "gyro_bias_rad_s", truth["gyro_bias_rad_s"], 1e-3);
  CHECK(j["scale_source"] == "lidar_ranges");
  REQUIRE(j["covariance"].size() == 9);
  CHECK(j["covariance"][0].size() == 9);
  for (const char* k : {"wheelbase_m", "wheel_diameter_left_m", "wheel_diameter_right_m", "lidar_mount", "scan_time_offset_s", "gyro_scale"})
    CHECK(j["excitation"].contains(k));
  // /tf_static composed in 3-D (base_footprint -> base_link -> laser, roll pi): upside down, yaw 0.5 + 3 deg.
  CHECK(m["tf_static"]["upside_down"] == true);
  CHECK(m["tf_static"]["yaw_rad"].get<double>() == Approx(0.5 + 3 * M_PI / 180).margin(1e-9));
  CHECK(m["tf_static"]["x_m"].get<double>() == Approx(0.10).margin(1e-9));
  // /tf_static has the yaw 3 deg off: named.
  CHECK_THAT(r.err, Contains("/tf_static's mount of the lidar") && Contains("yaw differs by"));
  // The --ros2 file: multipliers and the mount as a URDF origin with roll pi.
  const std::string yaml = Slurp((dir / "diff_drive.yaml").string());
  CHECK_THAT(yaml, Contains("wheel_separation_multiplier:") && Contains("left_wheel_radius_multiplier:"));
  const auto xyz = yaml.find("<origin xyz=\""), rpy = yaml.find("rpy=\"");
  REQUIRE(xyz != std::string::npos);
  REQUIRE(rpy != std::string::npos);
  double x = 0, y = 0, z = 0, roll = 0, pitch = 1, yaw = 0;
  REQUIRE(std::sscanf(yaml.c_str() + xyz + 13, "%lf %lf %lf", &x, &y, &z) == 3);
  REQUIRE(std::sscanf(yaml.c_str() + rpy + 5, "%lf %lf %lf", &roll, &pitch, &yaw) == 3);
  CHECK(x == Approx(m["x_m"].get<double>()).margin(1e-4));
  CHECK(y == Approx(m["y_m"].get<double>()).margin(1e-4));
  CHECK(z == Approx(0.18).margin(1e-4));  // kept from /tf_static (base_link -> laser)
  CHECK(roll == Approx(M_PI).margin(1e-6));
  CHECK(pitch == 0.0);
  CHECK(yaw == Approx(m["yaw_rad"].get<double>()).margin(1e-6));
  CHECK_THAT(yaml, Contains("static_transform_publisher") && Contains("--frame-id base_link --child-frame-id laser"));
}

TEST_CASE("calibrate-lidar: a namespaced /tf_static that agrees, found with --tf-static") {
  const auto truth = nlohmann::json::parse(Slurp((kLidar / "README-truth.json").string()))["drive_ns.mcap"];
  const auto r = RunCli("calibrate-lidar " + Q(kLidar / "drive_ns.mcap") + " --scan /scan --wheels /joint_states --tf-static "
                        "/robot1/tf_static --robot " + Q(kLidar / "robot.toml") + " --json -");
  INFO(r.err);
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["lidar_mount"]["upside_down"] == false);
  CheckWithin(j["lidar_mount"], "yaw_rad", truth["mount"][2], 0.005);
  CheckWithin(j, "scan_time_offset_s", truth["scan_time_offset_s"], 0.01);
  CHECK(j["lidar_mount"]["tf_static"]["frames"] == "base_link -> laser");
  CHECK_THAT(r.err, !Contains("disagrees"));
  CHECK(j["gyro_scale"].is_null());
  CHECK(j["excitation"].size() == 5);
}

// drive_odom.mcap: the controller's /odom beside /joint_states, and a lidar
// whose ranges read 1 % long (lidar_range_scale in the truth), so the scale
// from the ranges is 1 % long and a measured distance corrects it.
TEST_CASE("calibrate-lidar --odometry: the controller's odometry gives the wheels' fit, its scale resting on the ranges") {
  const auto truth = nlohmann::json::parse(Slurp((kLidar / "README-truth.json").string()))["drive_odom.mcap"];
  const double range_scale = truth["lidar_range_scale"];
  const std::string common = " --scan /scan --robot " + Q(kLidar / "robot.toml") + " --json -";
  const auto odom = RunCli("calibrate-lidar " + Q(kLidar / "drive_odom.mcap") + " --odometry /odom" + common);
  INFO(odom.err);
  REQUIRE(odom.status == 0);
  const auto j = nlohmann::json::parse(odom.out);
  CHECK(j["scale_source"] == "lidar_ranges");
  // Every length carries the ranges' 1 % (the 0.3 % on the wheels,
  // 5 mm on the mount, against the truth times the range scale).
  const auto& p = j["parameters"];
  CheckWithin(p, "wheelbase_m", range_scale * truth["wheelbase_m"].get<double>(), 0.003 * 0.2856);
  CheckWithin(p, "wheel_diameter_left_m", range_scale * truth["wheel_diameter_left_m"].get<double>(), 0.002 * 0.066);
  CheckWithin(p, "wheel_diameter_right_m", range_scale * truth["wheel_diameter_right_m"].get<double>(), 0.002 * 0.066);
  CHECK(p["wheelbase_m"].get<double>() > 1.005 * truth["wheelbase_m"].get<double>());  // the 1 % shows
  CheckWithin(j["lidar_mount"], "x_m", range_scale * truth["mount"][0].get<double>(), 0.005);
  CheckWithin(j["lidar_mount"], "y_m", range_scale * truth["mount"][1].get<double>(), 0.005);
  CheckWithin(j["lidar_mount"], "yaw_rad", truth["mount"][2], 0.0017);
  CheckWithin(j, "scan_time_offset_s", truth["scan_time_offset_s"], 0.005);
  // The joint positions of the same drive give the same fit: the odometry
  // (nominal radius and wheelbase, midpoint rule) inverts to the same travel.
  const auto joints = RunCli("calibrate-lidar " + Q(kLidar / "drive_odom.mcap") + " --wheels /joint_states" + common);
  REQUIRE(joints.status == 0);
  const auto jj = nlohmann::json::parse(joints.out);
  for (const char* k : {"wheelbase_m", "wheel_diameter_left_m", "wheel_diameter_right_m"})
    CHECK(p[k].get<double>() == Approx(jj["parameters"][k].get<double>()).epsilon(1e-4));
}

TEST_CASE("calibrate-lidar --distance-m: the overall scale from a measured distance, said so") {
  const auto truth = nlohmann::json::parse(Slurp((kLidar / "README-truth.json").string()))["drive_odom.mcap"];
  const double d = truth["distance_start_end_m"];
  const auto dir = TempDir("calibrate-lidar-distance");
  const std::string args = " --scan /scan --robot " + Q(kLidar / "robot.toml") + " --distance-m " + Decimal(d) + " --json " +
                           Q(dir / "out.json") + " --ros2 " + Q(dir / "diff_drive.yaml");
  const auto r = RunCli("calibrate-lidar " + Q(kLidar / "drive_odom.mcap") + " --odometry /odom" + args);
  INFO(r.out << r.err);
  REQUIRE(r.status == 0);
  CHECK_THAT(r.out, Contains("overall scale from  the measured distance (--distance-m)"));
  CHECK_THAT(r.err, !Contains("check the distance"));
  const auto j = nlohmann::json::parse(Slurp((dir / "out.json").string()));
  CHECK(j["scale_source"] == "distance_m");
  // Physical now: the 0.3 % on the written multipliers, against the
  // truth itself (the ranges' 1 % is gone).
  const auto& p = j["parameters"];
  CheckWithin(p, "wheelbase_m", truth["wheelbase_m"], 0.003 * 0.2856);
  CheckWithin(p, "wheel_diameter_left_m", truth["wheel_diameter_left_m"], 0.003 * 0.066);
  CheckWithin(p, "wheel_diameter_right_m", truth["wheel_diameter_right_m"], 0.003 * 0.066);
  CheckWithin(j["lidar_mount"], "x_m", truth["mount"][0], 0.005);
  CheckWithin(j["lidar_mount"], "y_m", truth["mount"][1], 0.005);
  const std::string yaml = Slurp((dir / "diff_drive.yaml").string());
  const auto at = yaml.find("wheel_separation_multiplier: ");
  REQUIRE(at != std::string::npos);
  const double mult = std::stod(yaml.substr(at + 29));
  CHECK(mult == Approx(truth["wheelbase_m"].get<double>() / 0.28).epsilon(0.003));
  // A distance 10 % short of the drive's is warned about (the scans measure more).
  const auto wrong = RunCli("calibrate-lidar " + Q(kLidar / "drive_odom.mcap") + " --wheels /joint_states --scan /scan --robot " +
                            Q(kLidar / "robot.toml") + " --distance-m " + Decimal(0.9 * d) + " --json -");
  REQUIRE(wrong.status == 0);
  CHECK_THAT(wrong.err, Contains("--distance-m") && Contains("check the distance"));
}

TEST_CASE("calibrate-lidar: bad input exits 1 or 2 naming the problem, writing nothing") {
  const auto dir = TempDir("calibrate-lidar-bad");
  const std::string bag = Q(kLidar / "drive_ns.mcap"), robot = " --robot " + Q(kLidar / "robot.toml");
  const std::string json = " --json " + Q(dir / "out.json");
  auto r = RunCli("calibrate-lidar " + bag + " --scan /laser_scan --wheels /joint_states" + robot + json);
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Contains("--scan topic /laser_scan is not in the recording") && Contains("/scan"));
  r = RunCli("calibrate-lidar " + bag + " --scan /joint_states --wheels /joint_states" + robot + json);
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Contains("must be sensor_msgs/msg/LaserScan"));
  r = RunCli("calibrate-lidar " + bag + " --scan /scan --wheels /joint_states --odometry /odom" + robot + json);
  CHECK(r.status == 2);
  r = RunCli("calibrate-lidar " + bag + " --scan /scan --wheels /joint_states --imu /scan" + robot + json);
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Contains("--imu topic /scan"));
  r = RunCli("calibrate-lidar " + Q(dir / "missing.mcap") + " --scan /scan --wheels /joint_states" + robot + json);
  CHECK(r.status == 1);
  r = RunCli("calibrate-lidar " + bag + " --scan /scan --wheels /joint_states --distance-m -3" + robot + json);
  CHECK(r.status == 2);
  CHECK_FALSE(std::filesystem::exists(dir / "out.json"));
}

TEST_CASE("calibrate-lidar: a drive that determines nothing exits 3, says what to drive, writes no --ros2") {
  // drive_still.mcap: the robot stands still for 40 s (long enough not to be
  // refused as short), so no parameter is excited.
  const auto dir = TempDir("calibrate-lidar-still");
  const std::string args = "calibrate-lidar " + Q(kLidar / "drive_still.mcap") + " --scan /scan --wheels /joint_states --imu /imu" +
                           " --robot " + Q(kLidar / "robot.toml") + " --ros2 " + Q(dir / "diff_drive.yaml");
  const auto r = RunCli(args);
  INFO(r.out << r.err);
  CHECK(r.status == 3);
  CHECK_THAT(r.err, Contains("the drive determines none of the wheel parameters") && Contains("nothing is written to --ros2"));
  // What to drive, for the wheelbase, the diameters and the mount.
  CHECK_THAT(r.err, Contains("add spot turns and loops, two full turns each way") &&
                        Contains("straight runs of at least 2 m") && Contains("the drive does not determine the wheelbase") &&
                        Contains("the drive does not determine the left wheel's diameter") &&
                        Contains("the drive does not determine the lidar's mount"));
  CHECK_FALSE(std::filesystem::exists(dir / "diff_drive.yaml"));
  CHECK(std::filesystem::is_empty(dir));
  // --json holds the refusal and the same advice (the contract: the JSON is
  // the report of the refusal; the parameters file is what is withheld).
  const auto j = RunCli(args + " --json -");
  CHECK(j.status == 3);
  const auto out = nlohmann::json::parse(j.out);
  CHECK(out.at("refused").get<std::string>() == "the drive determines none of the wheel parameters");
  for (const char* key : {"wheelbase_m", "wheel_diameter_left_m", "wheel_diameter_right_m", "lidar_mount"}) {
    INFO(key);
    CHECK(out.at("excitation").at(key).get<std::string>() == "not_excited");
  }
  CHECK_FALSE(std::filesystem::exists(dir / "diff_drive.yaml"));
}
