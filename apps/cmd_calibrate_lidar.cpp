// `umbmark calibrate-lidar BAG... --scan TOPIC (--wheels TOPIC | --odometry TOPIC)
//   --robot R.toml [--imu TOPIC] [--tf-static TOPIC] [--distance-m D] [--ros2 FILE] [--json FILE]`:
// the wheels, the lidar's mounting pose, the scan clock and the gyro jointly
// from one ordinary drive (contract section "Calibration from a bag without
// motion capture"). Reads with import/lidar_drive.hpp, computes with
// calibration/lidar_calibrate.hpp, prints.
#include <cmath>
#include <memory>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "calibration/lidar_calibrate.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "core/angles.hpp"
#include "core/errors.hpp"
#include "formats/ros2_params.hpp"
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

calibration::LidarCalibrationInput ToInput(const io::rosbag2::LidarDrive& d, const RobotParams& robot,
                                           std::optional<double> distance_m) {
  calibration::LidarCalibrationInput in;
  in.wheels.reserve(d.wheels.size());
  for (const auto& w : d.wheels) in.wheels.push_back({w.t_ns, w.left_m, w.right_m});
  in.scans = d.scans;
  in.gyro = d.gyro;
  in.nominal = robot;
  if (d.mount) in.tf_mount = calibration::StaticMount{d.mount->pose, d.mount->upside_down, d.mount->frames};
  in.distance_m = distance_m;
  return in;
}

nlohmann::json Interval(const std::array<double, 2>& a) { return {JsonNumber(a[0]), JsonNumber(a[1])}; }

nlohmann::json ToJson(const calibration::LidarCalibration& r, const io::rosbag2::LidarDrive& d) {
  nlohmann::json j;
  j["parameters"] = JsonParams(r.parameters);
  j["ros2_multipliers"] = {{"wheel_separation_multiplier", JsonNumber(r.wheel_separation_multiplier)},
                           {"left_wheel_radius_multiplier", JsonNumber(r.left_wheel_radius_multiplier)},
                           {"right_wheel_radius_multiplier", JsonNumber(r.right_wheel_radius_multiplier)}};
  j["lidar_mount"] = {{"x_m", JsonNumber(r.mount.x)},        {"y_m", JsonNumber(r.mount.y)},
                      {"yaw_rad", JsonNumber(r.mount.theta)}, {"upside_down", r.upside_down},
                      {"x_m_ci95", Interval(r.x_ci95)},       {"y_m_ci95", Interval(r.y_ci95)},
                      {"yaw_rad_ci95", Interval(r.yaw_ci95)}, {"frame", d.scan_frame}};
  if (d.mount) j["lidar_mount"]["tf_static"] = {{"x_m", JsonNumber(d.mount->pose.x)}, {"y_m", JsonNumber(d.mount->pose.y)},
                                                {"yaw_rad", JsonNumber(d.mount->pose.theta)},
                                                {"upside_down", d.mount->upside_down}, {"frames", d.mount->frames}};
  j["scan_time_offset_s"] = JsonNumber(r.time_offset_s);
  j["scan_time_offset_s_ci95"] = Interval(r.time_offset_ci95);
  j["gyro_scale"] = r.gyro_scale ? JsonNumber(*r.gyro_scale) : nlohmann::json(nullptr);
  j["gyro_bias_rad_s"] = r.gyro_bias_rad_s ? JsonNumber(*r.gyro_bias_rad_s) : nlohmann::json(nullptr);
  j["gyro_time_offset_s"] = r.gyro_time_offset_s ? JsonNumber(*r.gyro_time_offset_s) : nlohmann::json(nullptr);
  const std::size_t n = r.covariance_order.size();
  nlohmann::json cov = nlohmann::json::array();
  for (std::size_t i = 0; i < n; ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (std::size_t k = 0; k < n; ++k) row.push_back(JsonNumber(r.covariance[i * n + k]));
    cov.push_back(row);
  }
  j["covariance"] = cov;
  j["covariance_order"] = r.covariance_order;
  j["scale_source"] = r.scale_source;
  nlohmann::json ex = nlohmann::json::object(), what = nlohmann::json::object();
  for (const auto& e : r.excitation) {
    ex[e.key] = calibration::ExcitationToString(e.level);
    if (!e.what_to_drive.empty()) what[e.key] = e.what_to_drive;
  }
  j["excitation"] = ex;
  j["what_to_drive"] = what;
  j["drive"] = {{"duration_s", JsonNumber(r.duration_s)},      {"scans", r.scans},
                {"measurements", r.measurements},              {"outliers", r.fit.outliers},
                {"open_measurements", r.open_measurements},    {"lost_registrations", r.lost},
                {"straight_m", JsonNumber(r.straight_m)},      {"turned_left_rad", JsonNumber(r.turned_left_rad)},
                {"turned_right_rad", JsonNumber(r.turned_right_rad)},
                {"registration_scale", JsonNumber(r.fit.registration_scale)},
                {"wheel_noise_k", JsonNumber(r.fit.wheel_noise_k)}};
  const auto& lin = r.linear.params;
  j["linear_start"] = {{"wheelbase_m", JsonNumber(lin.wheelbase_m)},
                       {"wheel_diameter_left_m", JsonNumber(lin.c_left * r.parameters.wheel_diameter_left_m / r.fit.params.c_left)},
                       {"wheel_diameter_right_m", JsonNumber(lin.c_right * r.parameters.wheel_diameter_right_m / r.fit.params.c_right)},
                       {"x_m", JsonNumber(lin.mount.x)}, {"y_m", JsonNumber(lin.mount.y)}, {"yaw_rad", JsonNumber(lin.mount.theta)}};
  j["warnings"] = r.warnings;
  return j;
}

// The --ros2 file: the multipliers, and the mount as a comment block.
std::string Ros2File(const calibration::LidarCalibration& r, const io::rosbag2::LidarDrive& d, const RobotParams& robot,
                     const std::string& controller) {
  const std::string parent = d.mount ? d.mount->frames.substr(0, d.mount->frames.find(' ')) : "base_link";
  const std::string child = d.scan_frame.empty() ? "laser" : d.scan_frame;
  const double roll = r.upside_down ? kPi : 0.0;
  const std::string z = d.mount ? fmt::format("{:.4f}", d.mount->z_m) : "Z";
  std::vector<std::string> comment = {
      fmt::format("ros2_control diff_drive_controller parameters from umbmark calibrate-lidar ({} scale)",
                  r.scale_source == "distance_m" ? "measured distance" : "lidar ranges"),
      "Load with: ros2 param load /" + controller + " FILE (or add to the controller's --param-file list)",
      "",
      fmt::format("The lidar's mount, fitted ({}; z is not seen by a planar drive: {}):", r.upside_down ? "upside down" : "right way up",
                  d.mount ? "kept from /tf_static" : "replace Z by its height"),
      fmt::format("  URDF: <joint name=\"{}_joint\" type=\"fixed\"><parent link=\"{}\"/><child link=\"{}\"/>", child, parent, child),
      fmt::format("        <origin xyz=\"{:.4f} {:.4f} {}\" rpy=\"{:.6f} 0 {:.6f}\"/></joint>", r.mount.x, r.mount.y, z, roll,
                  r.mount.theta),
      fmt::format("  static transform: ros2 run tf2_ros static_transform_publisher --x {:.4f} --y {:.4f} --z {} --roll {:.6f} "
                  "--pitch 0 --yaw {:.6f} --frame-id {} --child-frame-id {}",
                  r.mount.x, r.mount.y, z, roll, r.mount.theta, parent, child),
      fmt::format("  scan clock: header stamp - scan time = {:+.4f} s", r.time_offset_s)};
  return io::FormatDiffDriveCalibration(
      controller, {r.wheel_separation_multiplier, r.left_wheel_radius_multiplier, r.right_wheel_radius_multiplier}, robot,
      comment);
}

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
  const io::rosbag2::LidarDrive drive = io::rosbag2::ReadLidarDrive(o.bags, robot, o.read);
  for (const auto& w : drive.warnings) fmt::print(stderr, "warning: {}\n", w);
  const calibration::LidarCalibration r = calibration::CalibrateLidar(ToInput(drive, robot, o.distance_m));
  for (const auto& w : r.warnings) fmt::print(stderr, "warning: {}\n", w);
  if (o.json.PrintText()) PrintText(r);
  nlohmann::json j = ToJson(r, drive);
  if (!r.wheels_determined) {
    std::string advice;
    for (const auto& e : r.excitation)
      if (!e.what_to_drive.empty()) advice += "\n  " + e.what_to_drive;
    j["refused"] = "the drive determines none of the wheel parameters";
    o.json.EmitAndListOutputs(j, {});
    fmt::print(stderr, "umbmark: quality gate failed: the drive determines none of the wheel parameters; nothing is "
                       "written to --ros2:{}\n", advice);
    return 3;
  }
  std::vector<std::string> written;
  if (!o.ros2.empty()) {
    outs.Write(o.ros2, Ros2File(r, drive, robot, o.controller));
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
