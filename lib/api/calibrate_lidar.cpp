// `calibrate-lidar` as a library call (see calibrate_lidar.hpp).
#include "api/calibrate_lidar.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "api/json.hpp"
#include "core/angles.hpp"
#include "core/errors.hpp"
#include "formats/ros2_params.hpp"
#include "output/atomic_write.hpp"

namespace umbmark::api {

namespace {

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

}  // namespace

nlohmann::json ToJson(const CalibrateLidarResult& result) {
  const calibration::LidarCalibration& r = result.calibration;
  const io::rosbag2::LidarDrive& d = result.recording;
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
  if (result.refused) j["refused"] = *result.refused;
  return j;
}

std::string CalibrateLidarRos2(const CalibrateLidarResult& result) {
  if (result.refused) throw QualityGateError("calibrate-lidar: " + *result.refused + "; no --ros2 file");
  const calibration::LidarCalibration& r = result.calibration;
  const io::rosbag2::LidarDrive& d = result.recording;
  const std::string& controller = result.controller;
  const RobotParams& robot = result.robot;
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

void WriteCalibrateLidarRos2(const CalibrateLidarResult& result, const std::string& path) {
  io::WriteFileAtomically(path, CalibrateLidarRos2(result));
}

std::string CalibrateLidarOptions::Check() const {
  if (bags.empty()) return "bags: at least one rosbag2 recording is needed";
  if (read.wheels_topic.empty() == read.odometry_topic.empty())
    return "exactly one wheel source is needed: --wheels TOPIC or --odometry TOPIC";
  if (auto e = read.Validate(); !e.empty()) return e;
  if (auto e = robot.Check(); !e.empty()) return "robot: " + e;
  if (distance_m && !(std::isfinite(*distance_m) && *distance_m > 0.0))
    return fmt::format("--distance-m: must be a finite number > 0 (got '{}')", *distance_m);
  if (controller.empty()) return "--controller: the controller's name is needed";
  return {};
}

CalibrateLidarResult CalibrateLidar(const CalibrateLidarOptions& options) {
  if (auto e = options.Check(); !e.empty()) throw InvalidOptions(e);
  CalibrateLidarResult r;
  r.robot = options.robot;
  r.controller = options.controller;
  r.recording = io::rosbag2::ReadLidarDrive(options.bags, options.robot, options.read);
  r.calibration = calibration::CalibrateLidar(ToInput(r.recording, options.robot, options.distance_m));
  if (!r.calibration.wheels_determined) r.refused = "the drive determines none of the wheel parameters";
  return r;
}

}  // namespace umbmark::api
