// Ground truth from the robot's own 2-D lidar and an optional gyro (`import
// rosbag2 --scan TOPIC [--imu TOPIC] [--scan-pose X,Y,YAW]`): after the
// importer has cut the runs, each run's scans are registered
// (scan_ground_truth.hpp: the still stretches around the run, the scans in
// between chained) and the registered poses are the run's ground truth.
#pragma once

#include <optional>

#include "ground_truth/source.hpp"

namespace umbmark::io::rosbag2 {

class ScanSource : public GroundTruthSource {
 public:
  explicit ScanSource(const GroundTruthOptions& o) : o_(o) {}

  std::string Name() const override { return "--scan " + o_.scan_topic; }
  bool CheckAgainstOdometry() const override { return false; }
  /// The lidar's topics are read on passes of their own (ReadRuns).
  std::vector<std::size_t> Open(const Bag&, std::size_t) override { return {}; }
  void OnMessage(CdrReader&, const BagMessage&, const TopicInfo&, std::size_t) override {}
  void EndOfPass(const Bag&, const std::string&, std::vector<std::string>&) override {}
  void ReadRuns(const Bag& bag, const RecordingRuns& runs, std::vector<std::string>& warnings) override;
  RunGroundTruth Run(std::size_t k) const override;
  std::size_t Messages() const override { return current_ ? current_->scans : 0; }
  void EndRecording() override;
  GroundTruthExtras Finish() override;

 private:
  GroundTruthOptions o_;
  std::optional<ScanGroundTruth> current_;     ///< the recording being imported
  std::vector<std::vector<GroundTruthSample>> run_samples_;  ///< its runs' registered poses
  std::vector<std::int64_t> run_gap_ns_;
  std::vector<ScanGroundTruth> recordings_;    ///< the finished ones (poses moved into the runs)
};

}  // namespace umbmark::io::rosbag2
