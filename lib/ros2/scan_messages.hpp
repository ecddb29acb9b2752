// Decoders for the lidar and gyro messages of `import rosbag2 --scan/--imu`,
// from their CDR bytes (cdr.hpp). Field order of the .msg definitions:
//   sensor_msgs/LaserScan  Header, float32 angle_min, angle_max,
//                          angle_increment, time_increment, scan_time,
//                          range_min, range_max, float32[] ranges, float32[] intensities
//   sensor_msgs/Imu        Header, Quaternion orientation, float64[9] orientation_covariance,
//                          Vector3 angular_velocity, float64[9] angular_velocity_covariance,
//                          Vector3 linear_acceleration, float64[9] linear_acceleration_covariance
// (REP 145: a covariance whose first element is -1 means the field is not
// provided.)
#pragma once

#include "ros2/cdr.hpp"
#include "ros2/messages.hpp"
#include "scan/laser_scan.hpp"

namespace umbmark::io::rosbag2 {

/// Decodes a LaserScan into `out` (reusing its storage); `frame_id` views
/// the message. out.t_ns is the header stamp.
void DecodeLaserScan(CdrReader& r, scan::LaserScan& out, std::string_view& frame_id);

struct ImuRate {
  Header header;
  double rate_z = 0.0;        ///< angular_velocity.z [rad/s]
  bool has_rate = true;       ///< false when angular_velocity_covariance[0] == -1
};
ImuRate DecodeImuRate(CdrReader& r);

}  // namespace umbmark::io::rosbag2
