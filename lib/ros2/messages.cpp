// ROS 2 message decoders (see messages.hpp).
#include "ros2/messages.hpp"

#include <cmath>

namespace umbmark::io::rosbag2 {

MessageType MessageTypeFromName(std::string_view type) {
  if (type == "sensor_msgs/msg/JointState") return MessageType::kJointState;
  if (type == "nav_msgs/msg/Odometry") return MessageType::kOdometry;
  if (type == "geometry_msgs/msg/PoseStamped") return MessageType::kPoseStamped;
  if (type == "geometry_msgs/msg/PoseWithCovarianceStamped") return MessageType::kPoseWithCovarianceStamped;
  if (type == "tf2_msgs/msg/TFMessage") return MessageType::kTfMessage;
  return MessageType::kOther;
}

bool IsPoseType(MessageType t) {
  return t == MessageType::kOdometry || t == MessageType::kPoseStamped ||
         t == MessageType::kPoseWithCovarianceStamped || t == MessageType::kTfMessage;
}

double PoseMsg::Yaw() const { return std::atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz)); }

Header ReadHeader(CdrReader& r) {
  Header h;
  const std::int32_t sec = r.Int32();
  const std::uint32_t nanosec = r.Uint32();
  h.stamp_ns = static_cast<std::int64_t>(sec) * 1000000000LL + static_cast<std::int64_t>(nanosec);
  h.frame_id = r.String();
  return h;
}

void DecodeJointState(CdrReader& r, JointStateMsg& out) {
  out.header = ReadHeader(r);
  const std::uint32_t names = r.SequenceLength(4);
  out.name.resize(names);
  for (auto& n : out.name) n = r.String();
  const std::uint32_t positions = r.SequenceLength(8);
  out.position.resize(positions);
  for (auto& p : out.position) p = r.Float64();
  // velocity[] only for its length (a velocity-only JointState is named as
  // such); a message cut after position[] is tolerated as before.
  out.velocity_count = 0;
  if (r.size() - r.offset() >= 4) {
    out.velocity_count = r.SequenceLength(8);
    r.Skip(out.velocity_count, 8);
  }
  // effort is not used.
}

namespace {

void ReadPose(CdrReader& r, PoseMsg& p) {
  p.x = r.Float64();
  p.y = r.Float64();
  p.z = r.Float64();
  p.qx = r.Float64();
  p.qy = r.Float64();
  p.qz = r.Float64();
  p.qw = r.Float64();
}

}  // namespace

PoseMsg DecodePoseStamped(CdrReader& r) {
  PoseMsg p;
  p.header = ReadHeader(r);
  ReadPose(r, p);
  return p;
}

PoseMsg DecodePoseWithCovarianceStamped(CdrReader& r) {
  PoseMsg p = DecodePoseStamped(r);
  r.Skip(36, 8);  // covariance
  return p;
}

PoseMsg DecodeOdometry(CdrReader& r) {
  PoseMsg p;
  p.header = ReadHeader(r);
  p.child_frame_id = r.String();
  ReadPose(r, p);
  r.Skip(36, 8);      // pose covariance
  r.Skip(6 + 36, 8);  // twist (linear, angular) and its covariance
  return p;
}

void DecodeTfMessage(CdrReader& r, std::vector<PoseMsg>& out) {
  out.clear();
  const std::uint32_t n = r.SequenceLength(4 + 4 + 4 + 4 + 7 * 8);
  for (std::uint32_t i = 0; i < n; ++i) {
    PoseMsg p;
    p.header = ReadHeader(r);
    p.child_frame_id = r.String();
    ReadPose(r, p);
    out.push_back(p);
  }
}

}  // namespace umbmark::io::rosbag2
