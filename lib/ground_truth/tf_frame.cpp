// Ground truth from one frame of a TFMessage topic (see tf_frame.hpp).
#include "ground_truth/tf_frame.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/errors.hpp"
#include "ground_truth/pose_topic.hpp"
#include "ros2/bag_text.hpp"

namespace umbmark::io::rosbag2 {

std::vector<std::size_t> TfFrameSource::Open(const Bag& bag, std::size_t wheel_topic) {
  gt_ = RequirePoseTopic(bag, topic_, wheel_topic).first;
  reading_ = frame_;
  tf_static_.reset();
  const auto st = bag.FindTopic("/tf_static");
  if (st && *st != gt_ && MessageTypeFromName(bag.topics()[*st].type) == MessageType::kTfMessage &&
      bag.topics()[*st].serialization_format == "cdr")
    tf_static_ = st;
  if (tf_static_) return {gt_, *tf_static_};
  return {gt_};
}

void TfFrameSource::OnMessage(CdrReader& r, const BagMessage& m, const TopicInfo& topic, std::size_t index) {
  if (tf_static_ && m.topic == *tf_static_) {
    DecodeTfMessage(r, msg_);
    for (const auto& p : msg_) tf_.Add(p, true);
    return;
  }
  OnTransforms(r, m, topic, index);
}

void TfFrameSource::OnTransforms(CdrReader& r, const BagMessage& m, const TopicInfo& topic, std::size_t index) {
  DecodeTfMessage(r, msg_);
  for (const auto& p : msg_) {
    tf_.Add(p, false);
    if (p.child_frame_id == reading_) {
      ++matches_;
      stream_.Add(p, m, topic, index);
    }
  }
}

// The frame's static anchor: the ground-truth topic read again for it.
void TfFrameSource::ReadAnchor(const Bag& bag, const std::string& anchor) {
  stream_.ClearSamples();
  reading_ = anchor;
  std::vector<bool> wanted(bag.topics().size(), false);
  wanted[gt_] = true;
  std::size_t index = 0;
  bag.Read(wanted, [&](const BagMessage& m) {
    const TopicInfo& topic = bag.topics()[m.topic];
    ++index;
    try {
      CdrReader r(m.data, m.size);
      OnTransforms(r, m, topic, index);
    } catch (const CdrError& e) {
      throw InputError(*m.file, fmt::format("{}: cannot decode: {}", WhereInBag(m, topic, index), e.what()));
    }
  });
}

void TfFrameSource::EndOfPass(const Bag& bag, const std::string& odometry_frame, std::vector<std::string>& warnings) {
  std::vector<std::string> odom_frames;
  if (!odometry_frame.empty()) odom_frames.push_back(odometry_frame);
  if (matches_ == 0) {
    const auto anchor = frame_.empty() ? std::nullopt : tf_.StaticAnchor(frame_);
    if (!anchor) {
      std::vector<std::string> lines;
      for (const auto& e : tf_.edges())
        lines.push_back(fmt::format("{} (parent {}{})", e.child, e.parent, e.is_static ? ", static" : ""));
      throw InputError(bag.path(), fmt::format("--ground-truth {}: no transform with child_frame_id '{}'{}; frames seen: {}",
                                               topic_, frame_, frame_.empty() ? " (set --ground-truth-frame)" : "",
                                               TrimmedList(lines, 30)));
    }
    ReadAnchor(bag, anchor->first);
    stream_.ComposeRight(anchor->second);
  }
  if (const auto odom = tf_.OdometryFrameAbove(frame_, odom_frames)) {
    const auto chain = tf_.Chain(frame_);
    std::vector<std::string> rev(chain.rbegin(), chain.rend());
    throw InputError(bag.path(), fmt::format(
        "--ground-truth {} --ground-truth-frame {}: the frame's chain {} runs through the odometry frame '{}' (REP 105: "
        "odom -> base_link is the robot's own wheel odometry), so this would compare the odometry with itself; choose "
        "the motion-capture frame (--list shows every frame with its parent)",
        topic_, frame_, fmt::join(rev, " -> "), *odom));
  }
  stream_.End(bag.path(), topic_, warnings);
}

void TfFrameSource::EndRecording() {
  stream_.Reset();
  tf_ = TfTree{};
  matches_ = 0;
}

}  // namespace umbmark::io::rosbag2
