// LaserScan and Imu decoders (see scan_messages.hpp).
#include "ros2/scan_messages.hpp"

namespace umbmark::io::rosbag2 {

void DecodeLaserScan(CdrReader& r, scan::LaserScan& out, std::string_view& frame_id) {
  const Header h = ReadHeader(r);
  out.t_ns = h.stamp_ns;
  frame_id = h.frame_id;
  out.angle_min = r.Read<float>();
  r.Read<float>();  // angle_max: implied by the count
  out.angle_increment = r.Read<float>();
  out.time_increment = r.Read<float>();
  out.scan_time = r.Read<float>();
  out.range_min = r.Read<float>();
  out.range_max = r.Read<float>();
  const std::uint32_t n = r.SequenceLength(4);
  out.ranges.resize(n);
  for (auto& v : out.ranges) v = r.Read<float>();
  // intensities are not used.
}

ImuRate DecodeImuRate(CdrReader& r) {
  ImuRate m;
  m.header = ReadHeader(r);
  r.Skip(4 + 9, 8);  // orientation, its covariance
  r.Read<double>();  // angular_velocity.x
  r.Read<double>();  // .y
  m.rate_z = r.Read<double>();
  m.has_rate = r.Read<double>() != -1.0;  // angular_velocity_covariance[0]
  r.Skip(8, 8);
  r.Skip(3 + 9, 8);  // linear acceleration, its covariance
  return m;
}

}  // namespace umbmark::io::rosbag2
