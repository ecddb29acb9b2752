// Wheel-travel sanity for `import rosbag2`: what real robots do to their
// JointState positions, detected before the travel becomes a campaign.
//   - positions wrapped into one revolution  -> unwrapped, with a warning
//   - a reset to 0 mid-bag (controller restart) -> stitched, with a warning
//   - any other jump (far faster than the wheel ever turns) -> refused
//   - one joint stuck while the other turns, or both joints the same
//     encoder (identical positions)          -> refused
//   - a gap in the topic inside a run with the wheels moving -> the run is
//     dropped by the importer, with a warning (FindGaps)
// Messages name the topic, the joint and the header stamp.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "ros2/bag_text.hpp"  // StampText, TrimmedList

namespace umbmark::io::rosbag2 {

/// One wheel-topic sample: cumulative travel of each wheel (JointState:
/// radians until converted, then metres; Odometry: pose x, y and yaw until
/// converted), its stamp and its 1-based message number on the topic.
struct WheelSample {
  std::int64_t t_ns = 0;
  double left = 0.0, right = 0.0;
  double yaw = 0.0;
  std::size_t msg = 0;
};

/// Names for the messages: the storage file, the topic and the joints.
struct WheelContext {
  std::string file, topic, left_joint, right_joint;
  bool odometry = false;  ///< travel read back from nav_msgs/Odometry (no joints)
};

/// Checks and repairs JointState positions (radians) in place: unwraps,
/// stitches resets, refuses other jumps and a shared joint. Throws
/// InputError naming topic, joint and stamp; warnings are appended.
void SanitizeJointPositions(std::vector<WheelSample>& s, const WheelContext& c, std::vector<std::string>& warnings);

/// Wheel travel read back from an Odometry topic (metres): a pose reset to
/// the origin (`at_origin[k]`: sample k's raw pose is at 0, 0, 0) is
/// stitched with a warning; any other jump is refused.
void SanitizeOdometryTravel(std::vector<WheelSample>& s, const std::vector<bool>& at_origin, const WheelContext& c,
                            std::vector<std::string>& warnings);

/// Refuses a wheel that never turns while the other travels (travel in
/// metres, after conversion).
void CheckStuckWheel(const std::vector<WheelSample>& s, const WheelContext& c);

/// A stretch with no wheel message far longer than the topic's usual
/// spacing while the wheels moved: sample k-1 -> k.
struct WheelGap {
  std::size_t k = 0;
  double seconds = 0.0, typical_s = 0.0, travel_m = 0.0;
};
/// Gaps longer than max(1 s, 10 x the median spacing) across which either
/// wheel moved (travel in metres).
std::vector<WheelGap> FindGaps(const std::vector<WheelSample>& s);

}  // namespace umbmark::io::rosbag2
