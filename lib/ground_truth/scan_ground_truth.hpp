// `import rosbag2 --scan TOPIC [--scan-pose X,Y,YAW] [--imu TOPIC]`: the
// ground truth of each run from the robot's own 2-D lidar (contract section
// "Ground truth from the robot's own lidar and gyro"), and the gyro's bias
// and scale against it. The registration itself is lib/scan (scan_track.hpp);
// this file reads the recording:
//   pass 1: /tf_static (the lidar's mounting pose: the robot's base frame,
//           base_link or base_footprint, to the scan's frame_id), the gyro,
//           the scan topic's frame_id;
//   pass 2: the scans, streamed into one RunTracker per run (memory does not
//           grow with the recording's length beyond one pose per scan).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/pose2.hpp"
#include "core/runs.hpp"
#include "formats/campaign_writer.hpp"
#include "ros2/bag.hpp"
#include "scan/gyro_calibration.hpp"
#include "scan/scan_track.hpp"

namespace umbmark::io::rosbag2 {

struct ScanSourceOptions {
  std::string scan_topic;             ///< sensor_msgs/msg/LaserScan
  std::string imu_topic;              ///< sensor_msgs/msg/Imu (optional)
  std::optional<Pose2> scan_pose;     ///< --scan-pose: the lidar in the robot frame, when /tf_static lacks it
  bool log_time = false;              ///< stamps: receive time instead of header.stamp
  std::int64_t origin_ns = 0;         ///< times in messages are given from here (the first wheel sample)
  scan::TrackOptions track;           ///< registration settings (mount is set from the above)
};

/// Cumulative wheel travel at a time, for the odometry's predictions.
struct WheelTravel {
  std::int64_t t_ns = 0;
  double left_m = 0.0, right_m = 0.0;
};

/// What one run's registration found.
struct ScanRunReport {
  std::string run;
  scan::TrackResult track;
  double gyro_heading_change_rad = 0.0;  ///< NaN without --imu
};

struct ScanGroundTruth {
  std::vector<ScanRunReport> runs;  ///< per window, in order; track.poses is the run's ground truth
  Pose2 mount;                      ///< the lidar's pose in the robot frame used
  std::string mount_source;         ///< "tf_static base_link -> laser", "--scan-pose", "origin"
  std::string scan_frame;
  std::size_t scans = 0, imu_messages = 0;
  std::optional<scan::GyroCalibration> gyro;
};

/// Registers the scans of `bag` for each run window. `wheels` (time order)
/// and `wheelbase_m` give the odometry's predictions. Throws InputError
/// naming the file and topic (zero scans, no transform for the scan's frame
/// and no --scan-pose, an IMU without angular velocity, undecodable
/// messages) or the run, the scan's time and the undetermined direction.
ScanGroundTruth ReadScanGroundTruth(const Bag& bag, const ScanSourceOptions& options,
                                    const std::vector<scan::RunWindow>& windows, const std::vector<std::string>& run_names,
                                    const std::vector<WheelTravel>& wheels, double wheelbase_m,
                                    std::vector<std::string>& warnings);

/// The manifest's [ground_truth] for scan ground truth: the noise of a
/// start or end pose (per pose: half the variance of a run's end relative to
/// its start), the RMS over all runs of the larger of the registration's
/// covariance and the single still scans' scatter over sqrt(scans).
GroundTruthNoise ScanGroundTruthNoise(const std::vector<ScanGroundTruth>& recordings);

/// Its further keys: source = "scan", the first recording's lidar pose
/// (scan_pose_x_m, _y_m, _yaw_rad, scan_pose_from), and the gyro's bias and
/// scale averaged over the recordings that have one.
std::vector<ManifestKey> ScanManifestKeys(const std::vector<ScanGroundTruth>& recordings);

}  // namespace umbmark::io::rosbag2
