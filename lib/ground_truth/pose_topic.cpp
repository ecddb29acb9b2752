// Ground truth from a motion-capture pose topic (see pose_topic.hpp).
#include "ground_truth/pose_topic.hpp"

#include <fmt/format.h>

#include "core/errors.hpp"
#include "ros2/bag_text.hpp"

namespace umbmark::io::rosbag2 {

std::pair<std::size_t, MessageType> RequirePoseTopic(const Bag& bag, const std::string& topic, std::size_t wheel_topic) {
  const std::size_t gt = RequireTopic(bag, topic, "--ground-truth");
  const TopicInfo& g = bag.topics()[gt];
  const MessageType type = MessageTypeFromName(g.type);
  if (!IsPoseType(type))
    throw InputError(bag.path(), fmt::format("--ground-truth topic {} has type {}, which holds no pose; ground truth must be "
                                             "geometry_msgs/msg/PoseStamped, geometry_msgs/msg/PoseWithCovarianceStamped, "
                                             "nav_msgs/msg/Odometry or tf2_msgs/msg/TFMessage", g.name, g.type));
  if (gt == wheel_topic) throw InputError(bag.path(), fmt::format("topic {} is both the wheel source and the ground truth", g.name));
  return {gt, type};
}

std::vector<std::size_t> PoseTopicSource::Open(const Bag& bag, std::size_t wheel_topic) {
  const auto [index, type] = RequirePoseTopic(bag, topic_, wheel_topic);
  type_ = type;
  return {index};
}

void PoseTopicSource::OnMessage(CdrReader& r, const BagMessage& m, const TopicInfo& topic, std::size_t index) {
  switch (type_) {
    case MessageType::kPoseStamped: stream_.Add(DecodePoseStamped(r), m, topic, index); break;
    case MessageType::kPoseWithCovarianceStamped: stream_.Add(DecodePoseWithCovarianceStamped(r), m, topic, index); break;
    case MessageType::kOdometry: stream_.Add(DecodeOdometry(r), m, topic, index); break;
    default: break;
  }
}

void PoseTopicSource::EndOfPass(const Bag& bag, const std::string&, std::vector<std::string>& warnings) {
  stream_.End(bag.path(), topic_, warnings);
}

}  // namespace umbmark::io::rosbag2
