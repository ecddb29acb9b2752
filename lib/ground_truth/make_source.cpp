// The registry of ground-truth sources and the one place that picks a
// source from the options (source.hpp). --ground-truth names a topic whose
// message type, known only once a recording is open, picks the pose-topic
// or the /tf source for that recording.
#include <map>
#include <memory>
#include <mutex>

#include <fmt/format.h>

#include "core/errors.hpp"

#include "ground_truth/pose_topic.hpp"
#include "ground_truth/scan_source.hpp"
#include "ground_truth/source.hpp"
#include "ground_truth/tf_frame.hpp"

namespace umbmark::io::rosbag2 {

namespace {

// --ground-truth TOPIC: per recording, the topic's type decides.
class TopicSource : public GroundTruthSource {
 public:
  explicit TopicSource(const GroundTruthOptions& o) : pose_(o), tf_(o), topic_(o.topic) {}

  std::string Name() const override { return "--ground-truth " + topic_; }
  bool CheckAgainstOdometry() const override { return true; }
  std::vector<std::size_t> Open(const Bag& bag, std::size_t wheel_topic) override {
    const MessageType type = RequirePoseTopic(bag, topic_, wheel_topic).second;
    current_ = type == MessageType::kTfMessage ? static_cast<GroundTruthSource*>(&tf_) : &pose_;
    return current_->Open(bag, wheel_topic);
  }
  void OnMessage(CdrReader& r, const BagMessage& m, const TopicInfo& topic, std::size_t index) override {
    current_->OnMessage(r, m, topic, index);
  }
  void EndOfPass(const Bag& bag, const std::string& odometry_frame, std::vector<std::string>& warnings) override {
    current_->EndOfPass(bag, odometry_frame, warnings);
  }
  std::optional<StampLag> Lag() const override { return current_->Lag(); }
  void ReadRuns(const Bag& bag, const RecordingRuns& runs, std::vector<std::string>& warnings) override {
    current_->ReadRuns(bag, runs, warnings);
  }
  RunGroundTruth Run(std::size_t k) const override { return current_->Run(k); }
  std::size_t Messages() const override { return current_->Messages(); }
  void EndRecording() override { current_->EndRecording(); }
  GroundTruthExtras Finish() override { return {}; }

 private:
  PoseTopicSource pose_;
  TfFrameSource tf_;
  std::string topic_;
  GroundTruthSource* current_ = &pose_;
};

// The sources by name: the built-in ones, and those a program registers.
struct Registry {
  std::mutex mutex;
  std::map<std::string, GroundTruthSourceFactory> sources{
      {"scan", [](const GroundTruthOptions& o) -> std::unique_ptr<GroundTruthSource> { return std::make_unique<ScanSource>(o); }},
      {"topic", [](const GroundTruthOptions& o) -> std::unique_ptr<GroundTruthSource> { return std::make_unique<TopicSource>(o); }}};
};

Registry& TheRegistry() {
  static Registry r;
  return r;
}

}  // namespace

void RegisterGroundTruthSource(const std::string& name, GroundTruthSourceFactory make) {
  Registry& r = TheRegistry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  r.sources[name] = std::move(make);
}

bool UnregisterGroundTruthSource(const std::string& name) {
  Registry& r = TheRegistry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  return r.sources.erase(name) > 0;
}

std::vector<std::string> GroundTruthSourceNames() {
  Registry& r = TheRegistry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  std::vector<std::string> names;
  for (const auto& [name, make] : r.sources) names.push_back(name);
  return names;
}

std::unique_ptr<GroundTruthSource> MakeGroundTruthSource(const GroundTruthOptions& o) {
  const std::string name = !o.source.empty() ? o.source : !o.scan_topic.empty() ? "scan" : !o.topic.empty() ? "topic" : "";
  if (name.empty()) return nullptr;
  GroundTruthSourceFactory make;
  {
    Registry& r = TheRegistry();
    const std::lock_guard<std::mutex> lock(r.mutex);
    const auto it = r.sources.find(name);
    if (it != r.sources.end()) make = it->second;
  }
  if (!make) {
    std::string known;
    for (const auto& n : GroundTruthSourceNames()) known += (known.empty() ? "" : ", ") + n;
    throw InvalidOptions(fmt::format("ground_truth_source = '{}': no ground-truth source of that name is registered "
                                     "(registered: {})", name, known));
  }
  std::unique_ptr<GroundTruthSource> source = make(o);
  if (!source) throw InvalidOptions(fmt::format("ground_truth_source = '{}': its factory made no source", name));
  return source;
}

}  // namespace umbmark::io::rosbag2
