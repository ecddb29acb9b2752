// Ground truth from the robot's lidar and gyro (see scan_source.hpp).
#include "ground_truth/scan_source.hpp"

#include <algorithm>
#include <cmath>

namespace umbmark::io::rosbag2 {

namespace {

constexpr double kStillM = 1e-6;  // a wheel is still when its travel changes less than this (as the importer's)

}  // namespace

// Each run's still stretches (from the first sample of the pause before to
// the last of the pause after) and the wheel travel for the odometry's
// predictions go to the registration.
void ScanSource::ReadRuns(const Bag& bag, const RecordingRuns& runs, std::vector<std::string>& warnings) {
  const std::vector<WheelTravel>& s = runs.wheels;
  auto still = [&](std::size_t i) {
    return std::abs(s[i].left_m - s[i - 1].left_m) < kStillM && std::abs(s[i].right_m - s[i - 1].right_m) < kStillM;
  };
  std::vector<scan::RunWindow> windows;
  std::vector<std::string> names;
  for (const auto& [a, b] : runs.spans) {
    std::size_t from = a, to = b;
    while (from > 0 && still(from)) --from;
    while (to + 1 < s.size() && still(to + 1)) ++to;
    windows.push_back({s[from].t_ns, s[a].t_ns, s[b].t_ns, s[to].t_ns});
    names.push_back(std::to_string(runs.first_run + names.size() + 1));
  }
  ScanSourceOptions so;
  so.scan_topic = o_.scan_topic;
  so.imu_topic = o_.imu_topic;
  so.scan_pose = o_.scan_pose;
  so.tf_static_topic = o_.tf_static_topic;
  so.upside_down = o_.scan_upside_down;
  so.left_joint = runs.left_joint;
  so.right_joint = runs.right_joint;
  so.log_time = o_.log_time;
  so.origin_ns = s.front().t_ns;
  current_ = ReadScanGroundTruth(bag, so, windows, names, s, runs.wheelbase_m, warnings);
  // Each run's poses as ground-truth samples, and the gap they need.
  run_samples_.clear();
  run_gap_ns_.clear();
  for (const auto& r : current_->runs) {
    std::vector<GroundTruthSample> out;
    double gap_s = 0.0;
    for (const auto& p : r.track.poses) {
      if (!out.empty()) gap_s = std::max(gap_s, static_cast<double>(p.t_ns - out.back().t_ns) * 1e-9);
      out.push_back({p.t_ns, p.pose.x, p.pose.y, p.pose.theta});
    }
    run_samples_.push_back(std::move(out));
    run_gap_ns_.push_back(static_cast<std::int64_t>(std::llround(std::max(o_.max_gap_s, gap_s) * 1e9)) + 1);
  }
}

RunGroundTruth ScanSource::Run(std::size_t k) const { return {&run_samples_[k], run_gap_ns_[k]}; }

void ScanSource::EndRecording() {
  if (!current_) return;
  for (auto& r : current_->runs) r.track.poses = {};  // now in the imported runs
  recordings_.push_back(std::move(*current_));
  current_.reset();
  run_samples_.clear();
  run_gap_ns_.clear();
}

GroundTruthExtras ScanSource::Finish() {
  GroundTruthExtras x;
  if (!recordings_.empty()) {
    x.noise = ScanGroundTruthNoise(recordings_);
    x.manifest_keys = ScanManifestKeys(recordings_);
  }
  x.scan = std::move(recordings_);
  recordings_.clear();
  return x;
}

}  // namespace umbmark::io::rosbag2
