// The poses of one ground-truth stream as the pose-topic and /tf sources
// read them: each message's pose checked (finite, a non-zero quaternion),
// its stamp (header or receive time) checked to increase, a repeated message
// (same stamp, same values) dropped and counted, and the header-minus-receive
// lag of each kept for the clock check. Shared by pose_topic.cpp and
// tf_frame.cpp.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "ground_truth/source.hpp"
#include "ros2/messages.hpp"

namespace umbmark::io::rosbag2 {

/// Refuses a pose that is not finite or whose quaternion is zero
/// (InputError naming message `index` of `topic`).
void CheckPoseFinite(const PoseMsg& p, const BagMessage& m, const TopicInfo& topic, std::size_t index);

class PoseStream {
 public:
  PoseStream(bool log_time, double max_gap_s) : log_time_(log_time), max_gap_s_(max_gap_s) {}

  /// One pose of message `index` of `topic` (InputError naming it when not
  /// finite, or when its stamp goes back).
  void Add(const PoseMsg& p, const BagMessage& m, const TopicInfo& topic, std::size_t index);
  /// Forgets the samples and lags (a second pass over another frame).
  void ClearSamples();
  /// Every pose composed with `offset` on the right (pose * offset).
  void ComposeRight(const Pose2& offset);
  /// After the stream: `topic` had no message -> InputError; repeated
  /// messages -> a warning; the heading unwrapped.
  void End(const std::string& file, const std::string& topic, std::vector<std::string>& warnings);

  std::optional<StampLag> Lag(const std::string& topic) const;
  RunGroundTruth All() const;
  std::size_t size() const { return samples_.size(); }
  void Reset();

 private:
  bool log_time_;
  double max_gap_s_;
  std::vector<GroundTruthSample> samples_;
  std::vector<double> lag_s_;
  std::size_t duplicates_ = 0;
};

}  // namespace umbmark::io::rosbag2
