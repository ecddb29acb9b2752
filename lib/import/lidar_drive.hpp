// The recordings of `umbmark calibrate-lidar`: wheel travel (through the
// rosbag2 import's wheel reading: JointState positions times the nominal
// radius, or Odometry inverted with the nominal wheelbase; all its checks),
// every scan of the LaserScan topic, the gyro's angular_velocity.z, and the
// lidar's mount from the /tf_static tree (composed in 3-D from the scan's
// frame_id up to base_link or base_footprint, so an upside-down lidar, roll
// pi, shows as such). Header stamps throughout. Several BAGs are read in
// the order given and must follow each other in time.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/pose2.hpp"
#include "core/robot.hpp"
#include "ground_truth/scan_ground_truth.hpp"
#include "scan/gyro_calibration.hpp"
#include "scan/laser_scan.hpp"

namespace umbmark::io::rosbag2 {

struct LidarDriveOptions {
  std::string scan_topic;                     ///< sensor_msgs/msg/LaserScan (required)
  std::string wheels_topic, odometry_topic;   ///< exactly one: JointState or Odometry
  std::string imu_topic;                      ///< sensor_msgs/msg/Imu (optional)
  std::string tf_static_topic = "/tf_static"; ///< tf2_msgs/msg/TFMessage; absent is fine
  /// Empty when valid, else a message naming the bad field.
  std::string Validate() const;
};

/// The mount /tf_static gives the scan's frame.
struct TfMount {
  Pose2 pose;                ///< x, y, yaw (the mirrored frame's yaw when upside down)
  bool upside_down = false;  ///< roll near pi
  double z_m = 0.0;          ///< height (not seen by a planar drive; kept for the --ros2 snippet)
  std::string frames;        ///< "base_link -> laser"
};

struct LidarDrive {
  std::vector<WheelTravel> wheels;   ///< travel as the odometry reports it, header stamps
  std::vector<scan::LaserScan> scans;
  std::vector<scan::GyroSample> gyro;
  std::optional<TfMount> mount;      ///< from the tf-static topic, when it reaches the scan's frame
  std::string scan_frame;
  std::vector<std::string> warnings;
};

/// Reads the drive. Throws InvalidOptions for bad options, InputError naming
/// the file and topic (a missing or mistyped topic, no scans, a scan's beam
/// layout changing, stamps that do not increase, an IMU without angular
/// velocity, recordings out of time order, anything the wheel import
/// refuses).
LidarDrive ReadLidarDrive(const std::vector<std::string>& bags, const RobotParams& robot, const LidarDriveOptions& options);

}  // namespace umbmark::io::rosbag2
