// Ground truth from one frame of a tf2_msgs/msg/TFMessage topic (`import
// rosbag2 --ground-truth /tf --ground-truth-frame FRAME`): the frame's own
// transforms, or, when it has none, those of the frame it is fixed to by
// /tf_static (read again on a second pass and composed with the static
// offset); never a frame whose chain runs through the odometry frame (REP
// 105: odom -> base_link is the robot's own wheel odometry).
#pragma once

#include "ground_truth/pose_stream.hpp"
#include "ground_truth/source.hpp"
#include "ros2/tf_tree.hpp"

namespace umbmark::io::rosbag2 {

class TfFrameSource : public GroundTruthSource {
 public:
  explicit TfFrameSource(const GroundTruthOptions& o)
      : topic_(o.topic), frame_(o.frame), stream_(o.log_time, o.max_gap_s) {}

  std::string Name() const override { return "--ground-truth " + topic_; }
  bool CheckAgainstOdometry() const override { return true; }
  std::vector<std::size_t> Open(const Bag& bag, std::size_t wheel_topic) override;
  void OnMessage(CdrReader& r, const BagMessage& m, const TopicInfo& topic, std::size_t index) override;
  void EndOfPass(const Bag& bag, const std::string& odometry_frame, std::vector<std::string>& warnings) override;
  std::optional<StampLag> Lag() const override { return stream_.Lag(topic_); }
  void ReadRuns(const Bag&, const RecordingRuns&, std::vector<std::string>&) override {}
  RunGroundTruth Run(std::size_t) const override { return stream_.All(); }
  std::size_t Messages() const override { return stream_.size(); }
  void EndRecording() override;
  GroundTruthExtras Finish() override { return {}; }

 private:
  void OnTransforms(CdrReader& r, const BagMessage& m, const TopicInfo& topic, std::size_t index);
  void ReadAnchor(const Bag& bag, const std::string& anchor);

  std::string topic_, frame_;
  PoseStream stream_;
  std::size_t gt_ = 0;
  std::optional<std::size_t> tf_static_;  ///< /tf_static, read with the ground truth
  std::string reading_;                   ///< the child frame whose transforms are taken
  TfTree tf_;                             ///< the ground-truth topic and /tf_static
  std::vector<PoseMsg> msg_;
  std::size_t matches_ = 0;
};

}  // namespace umbmark::io::rosbag2
