// `umbmark calibrate-lidar BAG... --scan TOPIC (--wheels TOPIC | --odometry TOPIC)
//   --robot R.toml [--imu TOPIC] [--tf-static TOPIC] [--distance-m D] [--ros2 FILE] [--json FILE]`:
// the wheels, the lidar's mounting pose, the scan clock and the gyro jointly
// from one ordinary drive (contract section "Calibration from a bag without
// motion capture"). The command's logic is api::CalibrateLidar
// (lib/api/calibrate_lidar.hpp); this file parses, calls it and prints.
#include <cmath>
#include <memory>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "api/calibrate_lidar.hpp"
#include "calibration/lidar_calibrate.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "core/angles.hpp"
#include "core/errors.hpp"
#include "import/lidar_drive.hpp"

namespace umbmark::cli {
namespace {

struct CalibrateLidarOptions {
  std::vector<std::string> bags;
  RobotFlags robot;
  io::rosbag2::LidarDriveOptions read;
  std::optional<double> distance_m;
  std::string ros2;
  std::string controller = "diff_drive_controller";
  JsonFlag json;
};

void PrintText(const calibration::LidarCalibration& r) {
  const std::size_t n = r.covariance_order.size();
  auto half = [&](std::size_t i) { return 1.96 * std::sqrt(std::max(0.0, r.covariance[i * n + i])); };
  fmt::print("calibrate-lidar: {:.0f} s of driving, {} scans, {} measurements ({} outliers, {} open, {} lost)\n", r.duration_s,
             r.scans, r.measurements, r.fit.outliers, r.open_measurements, r.lost);
  fmt::print("  straight {:.1f} m, turned {:.1f} rad left and {:.1f} rad right\n", r.straight_m, r.turned_left_rad,
             r.turned_right_rad);
  fmt::print("  wheelbase           {:.5f} m  +- {:.5f} (95 %)\n", r.parameters.wheelbase_m, half(0));
  fmt::print("  wheel diameter left {:.6f} m +- {:.6f}\n", r.parameters.wheel_diameter_left_m, half(1));
  fmt::print("  wheel diameter right {:.6f} m +- {:.6f}\n", r.parameters.wheel_diameter_right_m, half(2));
  fmt::print("  lidar mount         x {:.4f} +- {:.4f} m, y {:.4f} +- {:.4f} m, yaw {:.4f} +- {:.4f} rad ({:.2f} deg){}\n",
             r.mount.x, half(3), r.mount.y, half(4), r.mount.theta, half(5), Rad2Deg(r.mount.theta),
             r.upside_down ? ", upside down" : "");
  fmt::print("  scan clock offset   {:+.4f} +- {:.4f} s (header stamp minus the scan's time)\n", r.time_offset_s, half(6));
  if (r.gyro_scale)
    fmt::print("  gyro                scale {:.5f} +- {:.5f}, bias {:+.5f} +- {:.5f} rad/s\n", *r.gyro_scale, 1.96 * r.gyro_scale_sd,
               *r.gyro_bias_rad_s, 1.96 * r.gyro_bias_sd);
  if (r.gyro_time_offset_s)
    fmt::print("  gyro clock offset   {:+.4f} +- {:.4f} s (stamp minus the motion's time)\n", *r.gyro_time_offset_s,
               1.96 * r.gyro_time_offset_sd);
  fmt::print("  overall scale from  {}\n", r.scale_source == "distance_m" ? "the measured distance (--distance-m)"
                                                                           : "the lidar's ranges (--distance-m D to set it)");
  for (const auto& e : r.excitation)
    fmt::print("  {:<23} {}{}\n", e.key, calibration::ExcitationToString(e.level),
               e.what_to_drive.empty() ? "" : ": " + e.what_to_drive);
}

int RunCalibrateLidar(const CalibrateLidarOptions& o) {
  const RobotParams robot = o.robot.Resolve();
  io::OutputSet& outs = CommandOutputs();
  for (const auto& bag : o.bags) outs.AddInput(bag);
  if (!o.robot.robot_file.empty()) outs.AddInput(o.robot.robot_file);
  outs.AddOutput("--json", o.json.path);
  outs.AddOutput("--ros2", o.ros2);
  outs.Check();
  api::CalibrateLidarOptions co;
  co.bags = o.bags;
  co.robot = robot;
  co.read = o.read;
  co.distance_m = o.distance_m;
  co.controller = o.controller;
  const api::CalibrateLidarResult r = api::CalibrateLidar(co);
  for (const auto& w : r.recording.warnings) fmt::print(stderr, "warning: {}\n", w);
  for (const auto& w : r.calibration.warnings) fmt::print(stderr, "warning: {}\n", w);
  if (o.json.PrintText()) PrintText(r.calibration);
  const nlohmann::json j = api::ToJson(r);
  if (r.refused) {
    std::string advice;
    for (const auto& e : r.calibration.excitation)
      if (!e.what_to_drive.empty()) advice += "\n  " + e.what_to_drive;
    o.json.EmitAndListOutputs(j, {});
    fmt::print(stderr, "umbmark: quality gate failed: {}; nothing is written to --ros2:{}\n", *r.refused, advice);
    return 3;
  }
  std::vector<std::string> written;
  if (!o.ros2.empty()) {
    outs.Write(o.ros2, api::CalibrateLidarRos2(r));
    written.push_back(o.ros2 + " (ros2_control parameters and the lidar's mount)");
  }
  o.json.EmitAndListOutputs(j, written);
  return 0;
}

}  // namespace

Command SetupCalibrateLidar(CLI::App& parent) {
  auto opts = std::make_shared<CalibrateLidarOptions>();
  auto* app = parent.add_subcommand("calibrate-lidar",
                                    "Wheels, lidar mount, scan clock and gyro jointly from a bag of ordinary driving "
                                    "(no motion capture, no mount given)");
  app->add_option("BAG", opts->bags, "rosbag2 recording(s): a folder with metadata.yaml, or a .mcap / .db3 file")->required();
  app->add_option("--scan", opts->read.scan_topic, "sensor_msgs/msg/LaserScan topic")->required();
  auto* wheels = app->add_option("--wheels", opts->read.wheels_topic, "sensor_msgs/msg/JointState topic of the wheels");
  auto* odom = app->add_option("--odometry", opts->read.odometry_topic, "nav_msgs/msg/Odometry topic (instead of --wheels)");
  wheels->excludes(odom);
  odom->excludes(wheels);
  opts->robot.Bind(*app);
  app->add_option("--imu", opts->read.imu_topic, "sensor_msgs/msg/Imu topic: also fit the gyro's scale and bias");
  app->add_option("--tf-static", opts->read.tf_static_topic, "The static transform topic (namespaced trees)")
      ->capture_default_str();
  app->add_option("--distance-m", opts->distance_m,
                  "Measured distance [m] between where the drive starts and where it ends: the overall scale rests on it "
                  "instead of the lidar's ranges")
      ->check(Positive());
  app->add_option("--ros2", opts->ros2,
                  "Write the diff_drive_controller multipliers (YAML for ros2 param load), with the lidar's mount as a "
                  "URDF joint origin and a static transform in a comment block");
  app->add_option("--controller", opts->controller, "Controller name at the top of the --ros2 file")->capture_default_str();
  opts->json.Bind(*app);
  return {app, [opts] {
            if (opts->read.wheels_topic.empty() == opts->read.odometry_topic.empty())
              throw InvalidOptions("exactly one wheel source is needed: --wheels TOPIC or --odometry TOPIC");
            return RunCalibrateLidar(*opts);
          }};
}

}  // namespace umbmark::cli
