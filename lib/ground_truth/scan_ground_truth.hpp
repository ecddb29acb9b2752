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

#include <array>
#include <cstdint>
#include <map>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/pose2.hpp"
#include "core/runs.hpp"
#include "formats/campaign_writer.hpp"
#include "ros2/bag.hpp"
#include "ros2/messages.hpp"
#include "scan/gyro_calibration.hpp"
#include "scan/mount_check.hpp"
#include "scan/scan_track.hpp"

namespace umbmark::io::rosbag2 {

struct ScanSourceOptions {
  std::string scan_topic;             ///< sensor_msgs/msg/LaserScan
  std::string imu_topic;              ///< sensor_msgs/msg/Imu (optional)
  std::optional<Pose2> scan_pose;     ///< --scan-pose: the lidar in the robot frame, when /tf_static lacks it
  /// --tf-static: the static transform topic; empty = /tf_static, else the
  /// only topic named .../tf_static (a namespaced robot).
  std::string tf_static_topic;
  bool upside_down = false;           ///< --scan-upside-down: the lidar is mounted upside down (beams mirrored)
  std::string left_joint, right_joint;  ///< the wheel joints (for a message about swapped wheels)
  bool log_time = false;              ///< stamps: receive time instead of header.stamp
  std::int64_t origin_ns = 0;         ///< times in messages are given from here (the first wheel sample)
  scan::TrackOptions track;           ///< registration settings (mount is set from the above)
};

/// The lidar's mount as static transforms give it.
struct LidarMount {
  Pose2 pose;                 ///< x, y and the yaw of the scan's x axis in the base frame
  bool upside_down = false;   ///< the scan's z axis points down (roll or pitch pi): beams mirrored
  double tilt_rad = 0.0;      ///< angle between the scan plane and the floor
  std::string base_frame;     ///< where the chain ended (base_link or base_footprint when found)
};

/// The static transforms of a recording (/tf_static), composed in 3-D so
/// that a lidar mounted upside down (roll pi) is seen as such.
class StaticTransforms {
 public:
  /// False (nothing added) when the transform is not rigid (quaternion norm
  /// far from 1, a translation that is not finite).
  bool Add(const PoseMsg& transform);
  /// The chain from `frame` up to the first base_link or base_footprint (or
  /// as far as it goes); nullopt when `frame` has no transform.
  std::optional<LidarMount> Mount(const std::string& frame) const;
  /// "parent -> child, ..." for messages.
  std::string Describe() const;
  bool empty() const { return tf_.empty(); }

 private:
  struct Rigid3 {  // unit quaternion (w, x, y, z) and translation
    std::array<double, 4> q{1.0, 0.0, 0.0, 0.0};
    std::array<double, 3> t{};
    std::array<double, 3> Rotate(const std::array<double, 3>& v) const;
    Rigid3 Then(const Rigid3& o) const;  // this * o
  };
  std::map<std::string, std::pair<std::string, Rigid3>> tf_;  // child -> (parent, parent_T_child)
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
  bool upside_down = false;         ///< the scan plane's z axis points down: beam angles mirrored before use
  scan::MountEstimate mount_estimate;  ///< the mount as the scans and the wheels see it (mount_check.hpp)
  /// The scan clock against the wheels (scan_clock.hpp): header.stamp minus
  /// the time of the first ray, in the wheels' clock (0 when not determined).
  double scan_time_offset_s = 0.0;
  double clock_coarse_s = 0.0;     ///< the coarse step's first ray - stamp
  double clock_correlation = 0.0;  ///< of the scans' range changes with the wheel motion at it
  bool clock_determined = false;
  double sweep_s = 0.0;            ///< |time_increment| * (beams - 1) of the first scan (0: not given)
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
