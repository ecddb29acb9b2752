// The poses of one ground-truth stream (see pose_stream.hpp).
#include "ground_truth/pose_stream.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "ros2/bag_text.hpp"

namespace umbmark::io::rosbag2 {

namespace {

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

}  // namespace

void CheckPoseFinite(const PoseMsg& p, const BagMessage& m, const TopicInfo& t, std::size_t index) {
  for (double v : {p.x, p.y, p.qx, p.qy, p.qz, p.qw})
    if (!std::isfinite(v)) throw InputError(*m.file, fmt::format("{}: pose is not finite (NaN or infinite)", WhereInBag(m, t, index)));
  if (p.qx * p.qx + p.qy * p.qy + p.qz * p.qz + p.qw * p.qw < 1e-12)
    throw InputError(*m.file, fmt::format("{}: orientation quaternion is zero", WhereInBag(m, t, index)));
}

void PoseStream::Add(const PoseMsg& p, const BagMessage& m, const TopicInfo& topic, std::size_t index) {
  CheckPoseFinite(p, m, topic, index);
  const std::int64_t t = log_time_ ? m.log_time_ns : p.header.stamp_ns;
  if (!samples_.empty() && t <= samples_.back().t_ns) {
    const GroundTruthSample& b = samples_.back();
    const bool same = b.x == p.x && b.y == p.y && b.yaw == p.Yaw();
    if (t < b.t_ns || !same) StampGoesBack(b.t_ns, t, m, topic, index, log_time_, same);
    ++duplicates_;
    return;
  }
  lag_s_.push_back(static_cast<double>(p.header.stamp_ns - m.log_time_ns) * 1e-9);
  samples_.push_back({t, p.x, p.y, p.Yaw()});
}

void PoseStream::ClearSamples() {
  samples_.clear();
  lag_s_.clear();
}

void PoseStream::ComposeRight(const Pose2& offset) {
  for (auto& g : samples_) {
    const Pose2 p = Compose(Pose2{g.x, g.y, g.yaw}, offset);
    g = {g.t_ns, p.x, p.y, p.theta};
  }
}

void PoseStream::End(const std::string& file, const std::string& topic, std::vector<std::string>& warnings) {
  if (samples_.empty()) throw InputError(file, fmt::format("--ground-truth topic {} has no messages", topic));
  if (duplicates_ > 0)
    warnings.push_back(fmt::format("{}: topic {}: {} message(s) repeat the previous message's stamp and values; dropped",
                                   file, topic, duplicates_));
  // Unwrap the heading so that interpolation and total rotation are continuous.
  for (std::size_t i = 1; i < samples_.size(); ++i)
    samples_[i].yaw = samples_[i - 1].yaw + WrapAngle(samples_[i].yaw - samples_[i - 1].yaw);
}

std::optional<StampLag> PoseStream::Lag(const std::string& topic) const {
  if (samples_.empty()) return std::nullopt;
  return StampLag{Median(lag_s_), topic};
}

RunGroundTruth PoseStream::All() const {
  return {&samples_, static_cast<std::int64_t>(std::llround(max_gap_s_ * 1e9))};
}

void PoseStream::Reset() {
  ClearSamples();
  duplicates_ = 0;
}

}  // namespace umbmark::io::rosbag2
