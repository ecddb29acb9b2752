// The /tf and /tf_static transforms of a recording as a tree (child ->
// parent edges with their rates), for `--list` and for ground truth taken
// from a TFMessage topic:
//   - every frame is shown with its parent, so the motion-capture frame can
//     be chosen from `--list` alone;
//   - a frame whose chain to the root runs through the odometry frame
//     (REP 105: odom -> base_link is the robot's own wheel odometry) is not
//     ground truth, and is refused;
//   - a frame tied to a moving frame only by /tf_static offsets (a marker
//     mounted off the axle) gets the moving frame's pose composed with them.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/pose2.hpp"
#include "ros2/messages.hpp"

namespace umbmark::io::rosbag2 {

struct TfEdge {
  std::string parent, child;
  bool is_static = false;
  std::uint64_t count = 0;
  std::int64_t first_ns = 0, last_ns = 0;  ///< header stamps
  Pose2 last;                              ///< the latest transform, planar (parent_T_child)
  /// Messages per second over the stamps (0 for fewer than two).
  double RateHz() const;
};

class TfTree {
 public:
  /// Adds one transform (header.frame_id -> child_frame_id). At most
  /// kMaxEdges distinct edges are kept (further ones are counted only).
  void Add(const PoseMsg& t, bool is_static);
  const std::vector<TfEdge>& edges() const { return edges_; }
  std::size_t dropped_edges() const { return dropped_; }

  /// The frame's parent edge (a moving one first), or nullptr for a root.
  const TfEdge* ParentEdge(std::string_view child) const;
  /// [frame, parent, grandparent, ...] up to the root (cycles cut).
  std::vector<std::string> Chain(std::string_view frame) const;
  /// The first frame of the chain above `frame` that is an odometry frame
  /// (named `odom`, or containing it, or listed in `odom_frames`), if any.
  std::optional<std::string> OdometryFrameAbove(std::string_view frame, const std::vector<std::string>& odom_frames) const;
  /// When `frame` is tied to a frame M that has a moving parent only through
  /// static edges (either direction): M and the fixed offset M_T_frame.
  std::optional<std::pair<std::string, Pose2>> StaticAnchor(std::string_view frame) const;

  static constexpr std::size_t kMaxEdges = 4096;

 private:
  std::vector<TfEdge> edges_;
  std::map<std::string, std::size_t, std::less<>> index_;  // parent '\n' child '\n' static
  std::size_t dropped_ = 0;
};

/// The planar pose of a transform or pose message (x, y, yaw).
Pose2 PlanarPose(const PoseMsg& p);

}  // namespace umbmark::io::rosbag2
