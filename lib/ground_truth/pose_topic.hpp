// Ground truth from a motion-capture pose topic (`import rosbag2
// --ground-truth TOPIC`): geometry_msgs/msg/PoseStamped,
// PoseWithCovarianceStamped or nav_msgs/msg/Odometry, read in the importer's
// pass with the wheels and interpolated at the wheel samples (source.hpp).
#pragma once

#include "ground_truth/pose_stream.hpp"
#include "ground_truth/source.hpp"

namespace umbmark::io::rosbag2 {

class PoseTopicSource : public GroundTruthSource {
 public:
  explicit PoseTopicSource(const GroundTruthOptions& o) : topic_(o.topic), stream_(o.log_time, o.max_gap_s) {}

  std::string Name() const override { return "--ground-truth " + topic_; }
  bool CheckAgainstOdometry() const override { return true; }
  std::vector<std::size_t> Open(const Bag& bag, std::size_t wheel_topic) override;
  void OnMessage(CdrReader& r, const BagMessage& m, const TopicInfo& topic, std::size_t index) override;
  void EndOfPass(const Bag& bag, const std::string& odometry_frame, std::vector<std::string>& warnings) override;
  std::optional<StampLag> Lag() const override { return stream_.Lag(topic_); }
  void ReadRuns(const Bag&, const RecordingRuns&, std::vector<std::string>&) override {}
  RunGroundTruth Run(std::size_t) const override { return stream_.All(); }
  std::size_t Messages() const override { return stream_.size(); }
  void EndRecording() override { stream_.Reset(); }
  GroundTruthExtras Finish() override { return {}; }

 private:
  std::string topic_;
  MessageType type_ = MessageType::kOther;
  PoseStream stream_;
};

/// The checks every pose-carrying --ground-truth topic passes: present, CDR,
/// a pose type, not the wheel topic. Returns its index and type.
std::pair<std::size_t, MessageType> RequirePoseTopic(const Bag& bag, const std::string& topic, std::size_t wheel_topic);

}  // namespace umbmark::io::rosbag2
