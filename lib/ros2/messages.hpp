// Decoders for the ROS 2 message types `import rosbag2` reads, from their CDR
// bytes (cdr.hpp). Field order follows the .msg definitions:
//   builtin_interfaces/Time      int32 sec, uint32 nanosec
//   std_msgs/Header              Time stamp, string frame_id
//   sensor_msgs/JointState       Header, string[] name, float64[] position, velocity[], effort[]
//   geometry_msgs/Pose           Point position (x, y, z), Quaternion orientation (x, y, z, w)
//   geometry_msgs/PoseStamped    Header, Pose
//   geometry_msgs/PoseWithCovarianceStamped  Header, Pose, float64[36] covariance
//   nav_msgs/Odometry            Header, string child_frame_id, PoseWithCovariance, TwistWithCovariance
//   geometry_msgs/TransformStamped  Header, string child_frame_id, Vector3 translation, Quaternion rotation
//   tf2_msgs/TFMessage           TransformStamped[] transforms
// Only the fields the importer uses are kept; views point into the message.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "ros2/cdr.hpp"

namespace umbmark::io::rosbag2 {

/// The message types the importer understands, by their ROS 2 type name.
enum class MessageType { kJointState, kOdometry, kPoseStamped, kPoseWithCovarianceStamped, kTfMessage, kOther };
MessageType MessageTypeFromName(std::string_view type);
/// True for the types that can serve as ground truth (a pose source).
bool IsPoseType(MessageType t);

struct Header {
  std::int64_t stamp_ns = 0;  ///< sec * 1e9 + nanosec
  std::string_view frame_id;
};

struct JointStateMsg {
  Header header;
  std::vector<std::string_view> name;
  std::vector<double> position;
  std::size_t velocity_count = 0;  ///< length of velocity[] (values not kept)
};

/// A planar-relevant pose: position and orientation quaternion.
struct PoseMsg {
  Header header;
  std::string_view child_frame_id;  ///< Odometry and transforms; empty otherwise
  double x = 0, y = 0, z = 0;
  double qx = 0, qy = 0, qz = 0, qw = 1;
  /// Heading: the yaw of the quaternion (z-y-x convention), in (-pi, pi].
  double Yaw() const;
};

Header ReadHeader(CdrReader& r);
/// Decodes into `out`, reusing its storage (no allocation once warm).
void DecodeJointState(CdrReader& r, JointStateMsg& out);
PoseMsg DecodePoseStamped(CdrReader& r);
PoseMsg DecodePoseWithCovarianceStamped(CdrReader& r);
PoseMsg DecodeOdometry(CdrReader& r);
/// All transforms of a TFMessage (appended to `out` after clearing it).
void DecodeTfMessage(CdrReader& r, std::vector<PoseMsg>& out);

}  // namespace umbmark::io::rosbag2
