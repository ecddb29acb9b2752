// `umbmark calibrate-lidar` as a library call: the wheels, the lidar's
// mounting pose, the scan clock and the gyro jointly from one ordinary drive
// recorded in rosbag2 bags.
//   CalibrateLidar(CalibrateLidarOptions) -> CalibrateLidarResult;
//   ToJson(result) is the command's --json document; CalibrateLidarRos2 /
//   WriteCalibrateLidarRos2 its --ros2 file.
// Files: reads the bags; WriteCalibrateLidarRos2 writes one file atomically.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "calibration/lidar_calibrate.hpp"
#include "core/robot.hpp"
#include "import/lidar_drive.hpp"

namespace umbmark::api {

struct CalibrateLidarOptions {
  /// BAG...: rosbag2 recordings (a folder with metadata.yaml, a .mcap or a
  /// .db3), at least one, in time order.
  std::vector<std::string> bags;
  /// The parameters the odometry used (--robot and overrides, resolved:
  /// RobotSource::Resolve). Required: RobotParams::Check().
  RobotParams robot;
  /// --scan (required), --wheels or --odometry (exactly one), --imu
  /// (optional: also the gyro), --tf-static (default "/tf_static").
  io::rosbag2::LidarDriveOptions read;
  /// --distance-m: measured distance [m] between the drive's start and end;
  /// unset = the overall scale rests on the lidar's ranges.
  std::optional<double> distance_m;
  /// --controller: the name at the top of the --ros2 file.
  std::string controller = "diff_drive_controller";

  /// "" when usable, else a message naming the bad field.
  std::string Check() const;
};

/// What `calibrate-lidar` gives. The JSON's keys come from `calibration`
/// (parameters, ros2_multipliers, lidar_mount, scan_time_offset_s[_ci95],
/// gyro_scale, gyro_bias_rad_s, gyro_time_offset_s, covariance[_order], scale_source,
/// excitation, what_to_drive, drive, linear_start, warnings), the lidar
/// frame and /tf_static mount from `recording`, and `refused`.
struct CalibrateLidarResult {
  calibration::LidarCalibration calibration;
  /// What was read from the bags (its `warnings` are not in the JSON: the
  /// command prints them on stderr).
  io::rosbag2::LidarDrive recording;
  /// The robot the odometry used (for the --ros2 file).
  RobotParams robot;
  std::string controller;
  /// Set when the drive determines none of the wheel parameters (the
  /// command then exits 3 and writes no --ros2 file).
  std::optional<std::string> refused;
};

/// Reads the bags and calibrates. Throws InvalidOptions (Check()'s
/// message), InputError naming the file and topic.
CalibrateLidarResult CalibrateLidar(const CalibrateLidarOptions& options);

/// The command's JSON document (the contract's `calibrate-lidar --json`).
nlohmann::json ToJson(const CalibrateLidarResult& result);

/// The --ros2 file: the diff_drive_controller multipliers (YAML for `ros2
/// param load`), the lidar's mount as a URDF joint and a static transform in
/// a comment block. Throws QualityGateError when the result is refused.
std::string CalibrateLidarRos2(const CalibrateLidarResult& result);
/// Writes CalibrateLidarRos2(result) to `path` atomically.
void WriteCalibrateLidarRos2(const CalibrateLidarResult& result, const std::string& path);

}  // namespace umbmark::api
