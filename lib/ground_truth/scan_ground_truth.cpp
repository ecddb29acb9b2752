// Ground truth from the lidar and gyro of a recording (see scan_ground_truth.hpp).
#include "ground_truth/scan_ground_truth.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include <fmt/format.h>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "ros2/messages.hpp"
#include "ros2/scan_messages.hpp"

namespace umbmark::io::rosbag2 {

namespace {

double Seconds(std::int64_t ns) { return static_cast<double>(ns) * 1e-9; }

std::size_t RequireTyped(const Bag& bag, const std::string& name, const char* flag, const char* type) {
  const auto idx = bag.FindTopic(name);
  if (!idx) {
    std::string topics;
    for (const auto& t : bag.topics()) topics += fmt::format("\n  {}  {}  ({} messages)", t.name, t.type, t.count);
    throw InputError(bag.path(), fmt::format("{} topic {} is not in the recording; its topics are:{}", flag, name,
                                             topics.empty() ? " none" : topics));
  }
  const TopicInfo& t = bag.topics()[*idx];
  if (t.type != type) throw InputError(bag.path(), fmt::format("{} topic {} has type {}; it must be {}", flag, name, t.type, type));
  if (t.serialization_format != "cdr")
    throw InputError(bag.path(), fmt::format("topic {} is serialized as '{}', only cdr is supported", name, t.serialization_format));
  return *idx;
}

// The wheel odometry (nominal wheelbase, arcs) at any time, interpolated.
class Odometry {
 public:
  Odometry(const std::vector<WheelTravel>& w, double b) {
    Pose2 p;
    for (std::size_t k = 0; k < w.size(); ++k) {
      if (k > 0) {
        const double dl = w[k].left_m - w[k - 1].left_m, dr = w[k].right_m - w[k - 1].right_m;
        const double ds = 0.5 * (dl + dr), dth = (dr - dl) / b, h = 0.5 * dth;
        const double chord = std::abs(h) < 1e-12 ? ds : ds * std::sin(h) / h;
        p = {p.x + chord * std::cos(p.theta + h), p.y + chord * std::sin(p.theta + h), p.theta + dth};
      }
      t_.push_back(w[k].t_ns);
      pose_.push_back(p);
    }
  }
  Pose2 operator()(std::int64_t t) const {
    if (t_.empty()) return {};
    if (t <= t_.front()) return pose_.front();
    if (t >= t_.back()) return pose_.back();
    const auto k = static_cast<std::size_t>(std::upper_bound(t_.begin(), t_.end(), t) - t_.begin());
    const double u = static_cast<double>(t - t_[k - 1]) / static_cast<double>(t_[k] - t_[k - 1]);
    const Pose2& a = pose_[k - 1];
    const Pose2& b = pose_[k];
    return {a.x + u * (b.x - a.x), a.y + u * (b.y - a.y), a.theta + u * (b.theta - a.theta)};
  }

 private:
  std::vector<std::int64_t> t_;
  std::vector<Pose2> pose_;
};

struct FirstPass {
  std::map<std::string, std::pair<std::string, Pose2>> tf;  // child -> (parent, parent_T_child)
  bool has_tf_static = false;
  std::string scan_frame;
  std::size_t scans = 0;
  std::vector<scan::GyroSample> gyro;
};

std::string Where(const BagMessage& m, const TopicInfo& t, std::size_t index) {
  return m.offset > 0 ? fmt::format("topic {} ({}), message {} (record at byte {})", t.name, t.type, index, m.offset)
                      : fmt::format("topic {} ({}), message {}", t.name, t.type, index);
}

// /tf_static, the gyro and the scan topic's frame and count.
FirstPass ReadFirstPass(const Bag& bag, std::size_t scan_topic, std::optional<std::size_t> imu_topic,
                        const ScanSourceOptions& o) {
  FirstPass f;
  std::vector<bool> wanted(bag.topics().size(), false);
  wanted[scan_topic] = true;
  const auto tf_topic = bag.FindTopic("/tf_static");
  if (tf_topic && bag.topics()[*tf_topic].type == "tf2_msgs/msg/TFMessage") {
    wanted[*tf_topic] = true;
    f.has_tf_static = true;
  }
  if (imu_topic) wanted[*imu_topic] = true;
  std::vector<PoseMsg> tf;
  std::size_t imu_index = 0;
  bag.Read(wanted, [&](const BagMessage& m) {
    const TopicInfo& topic = bag.topics()[m.topic];
    try {
      CdrReader r(m.data, m.size);
      if (m.topic == scan_topic) {
        if (f.scans++ == 0) f.scan_frame = std::string(ReadHeader(r).frame_id);
      } else if (imu_topic && m.topic == *imu_topic) {
        ++imu_index;
        const ImuRate g = DecodeImuRate(r);
        if (!g.has_rate)
          throw InputError(*m.file, fmt::format("{}: the IMU has no angular velocity (angular_velocity_covariance[0] "
                                                "is -1); --imu {} cannot give a heading", Where(m, topic, imu_index), topic.name));
        if (!std::isfinite(g.rate_z))
          throw InputError(*m.file, fmt::format("{}: angular_velocity.z is not finite", Where(m, topic, imu_index)));
        const std::int64_t t = o.log_time ? m.log_time_ns : g.header.stamp_ns;
        if (!f.gyro.empty() && t <= f.gyro.back().t_ns)
          throw InputError(*m.file, fmt::format("{}: stamp {:.9f} s does not increase", Where(m, topic, imu_index), Seconds(t)));
        f.gyro.push_back({t, g.rate_z});
      } else {
        DecodeTfMessage(r, tf);
        for (const auto& p : tf) f.tf[std::string(p.child_frame_id)] = {std::string(p.header.frame_id), Pose2{p.x, p.y, p.Yaw()}};
      }
    } catch (const CdrError& e) {
      throw InputError(*m.file, fmt::format("topic {}: cannot decode: {}", topic.name, e.what()));
    }
  });
  return f;
}

bool IsBaseFrame(const std::string& f) { return f == "base_link" || f == "base_footprint"; }

// The lidar's pose in the robot frame: /tf_static up from the scan's frame to
// the first base frame, else --scan-pose, else the origin.
void ResolveMount(const Bag& bag, const FirstPass& f, const ScanSourceOptions& o, ScanGroundTruth& out,
                  std::vector<std::string>& warnings) {
  if (IsBaseFrame(f.scan_frame)) {
    out.mount_source = fmt::format("scan frame {} is the robot's base frame", f.scan_frame);
    return;
  }
  if (f.tf.count(f.scan_frame) > 0) {
    Pose2 pose;
    std::string cur = f.scan_frame;
    std::set<std::string> seen;
    while (!IsBaseFrame(cur) && f.tf.count(cur) > 0 && seen.insert(cur).second) {
      const auto& [parent, t] = f.tf.at(cur);
      pose = Compose(t, pose);
      cur = parent;
    }
    if (!IsBaseFrame(cur))
      warnings.push_back(fmt::format("{}: /tf_static reaches no base_link or base_footprint from {}; the lidar pose is "
                                     "taken relative to {}", bag.path(), f.scan_frame, cur));
    out.mount = pose;
    out.mount_source = fmt::format("tf_static {} -> {}", cur, f.scan_frame);
    if (o.scan_pose && (std::abs(o.scan_pose->x - pose.x) > 1e-3 || std::abs(o.scan_pose->y - pose.y) > 1e-3 ||
                        std::abs(WrapAngle(o.scan_pose->theta - pose.theta)) > 1e-3))
      warnings.push_back(fmt::format("{}: --scan-pose {},{},{} differs from /tf_static's {},{},{}; /tf_static is used",
                                     bag.path(), o.scan_pose->x, o.scan_pose->y, o.scan_pose->theta, pose.x, pose.y, pose.theta));
    return;
  }
  if (o.scan_pose) {
    out.mount = *o.scan_pose;
    out.mount_source = "--scan-pose";
    return;
  }
  if (f.has_tf_static) {
    std::string frames;
    for (const auto& [child, v] : f.tf) frames += (frames.empty() ? "" : ", ") + v.first + " -> " + child;
    throw InputError(bag.path(), fmt::format("--scan {}: its frame_id '{}' has no transform in /tf_static ({}) and no "
                                             "--scan-pose X,Y,YAW was given", o.scan_topic, f.scan_frame,
                                             frames.empty() ? "empty" : frames));
  }
  out.mount_source = "origin";
  warnings.push_back(fmt::format("{}: no /tf_static and no --scan-pose: the lidar ({}) is taken to sit at the axle "
                                 "midpoint facing forward", bag.path(), f.scan_frame));
}

// Streams the scans into one tracker per run; a run's tracker finishes as
// soon as the scans pass its window (its poses are all that is kept).
void TrackScans(const Bag& bag, std::size_t scan_topic, const ScanSourceOptions& o,
                const std::vector<scan::RunWindow>& windows, const std::vector<std::string>& names, const Odometry& odo,
                ScanGroundTruth& out) {
  const std::function<Pose2(std::int64_t)> odometry = [&odo](std::int64_t t) { return odo(t); };
  scan::TrackOptions track = o.track;
  track.mount = out.mount;
  std::vector<std::optional<scan::RunTracker>> trackers(windows.size());
  out.runs.resize(windows.size());
  std::size_t next = 0, index = 0;  // first run not yet finished
  std::int64_t prev_t = std::numeric_limits<std::int64_t>::min();
  scan::LaserScan s;
  std::string_view frame;
  std::vector<bool> wanted(bag.topics().size(), false);
  wanted[scan_topic] = true;
  const TopicInfo& topic = bag.topics()[scan_topic];
  auto fail = [&](std::size_t k, std::int64_t t, const char* what) {
    throw InputError(bag.path(), fmt::format("run {}, --scan {} at t = {:.3f} s (stamp {:.3f} s): {}", names[k], o.scan_topic,
                                             Seconds(t - o.origin_ns), Seconds(t), what));
  };
  auto finish = [&](std::size_t k) {
    try {
      if (!trackers[k]) trackers[k].emplace(windows[k], odometry, track);
      out.runs[k].run = names[k];
      out.runs[k].track = trackers[k]->Finish();
      trackers[k].reset();
    } catch (const scan::DegenerateScene& e) {
      fail(k, e.t_ns(), e.what());
    } catch (const scan::RegistrationFailed& e) {
      fail(k, e.t_ns(), e.what());
    }
  };
  bag.Read(wanted, [&](const BagMessage& m) {
    ++index;
    try {
      CdrReader r(m.data, m.size);
      DecodeLaserScan(r, s, frame);
    } catch (const CdrError& e) {
      throw InputError(*m.file, fmt::format("{}: cannot decode: {}", Where(m, topic, index), e.what()));
    }
    if (o.log_time) s.t_ns = m.log_time_ns;
    if (!(std::isfinite(s.angle_min) && std::isfinite(s.angle_increment) && s.angle_increment != 0.0))
      throw InputError(*m.file, fmt::format("{}: angle_min {} / angle_increment {} is not a usable beam layout",
                                            Where(m, topic, index), s.angle_min, s.angle_increment));
    if (s.t_ns <= prev_t)
      throw InputError(*m.file, fmt::format("{}: stamp {:.9f} s does not increase (previous {:.9f} s){}", Where(m, topic, index),
                                            Seconds(s.t_ns), Seconds(prev_t), o.log_time ? "" : "; try --time log"));
    prev_t = s.t_ns;
    while (next < windows.size() && s.t_ns > windows[next].still_to_ns) finish(next++);
    for (std::size_t k = next; k < windows.size() && windows[k].still_from_ns <= s.t_ns; ++k) {
      try {
        if (!trackers[k]) trackers[k].emplace(windows[k], odometry, track);
        trackers[k]->Add(s);
      } catch (const scan::DegenerateScene& e) {
        fail(k, e.t_ns(), e.what());
      } catch (const scan::RegistrationFailed& e) {
        fail(k, e.t_ns(), e.what());
      } catch (const std::invalid_argument& e) {
        throw InputError(*m.file, fmt::format("{}: {}", Where(m, topic, index), e.what()));
      }
    }
  });
  while (next < windows.size()) finish(next++);
}

}  // namespace

ScanGroundTruth ReadScanGroundTruth(const Bag& bag, const ScanSourceOptions& o, const std::vector<scan::RunWindow>& windows,
                                    const std::vector<std::string>& run_names, const std::vector<WheelTravel>& wheels,
                                    double wheelbase_m, std::vector<std::string>& warnings) {
  ScanGroundTruth out;
  const std::size_t scan_topic = RequireTyped(bag, o.scan_topic, "--scan", "sensor_msgs/msg/LaserScan");
  std::optional<std::size_t> imu_topic;
  if (!o.imu_topic.empty()) imu_topic = RequireTyped(bag, o.imu_topic, "--imu", "sensor_msgs/msg/Imu");
  const FirstPass f = ReadFirstPass(bag, scan_topic, imu_topic, o);
  if (f.scans == 0) throw InputError(bag.path(), fmt::format("--scan topic {} has no messages", o.scan_topic));
  if (imu_topic && f.gyro.empty()) throw InputError(bag.path(), fmt::format("--imu topic {} has no messages", o.imu_topic));
  out.scans = f.scans;
  out.imu_messages = f.gyro.size();
  out.scan_frame = f.scan_frame;
  ResolveMount(bag, f, o, out, warnings);
  TrackScans(bag, scan_topic, o, windows, run_names, Odometry(wheels, wheelbase_m), out);
  for (auto& r : out.runs) r.gyro_heading_change_rad = std::numeric_limits<double>::quiet_NaN();
  if (imu_topic) {
    std::vector<std::pair<std::int64_t, std::int64_t>> still;
    std::vector<scan::GyroRun> turns;
    for (std::size_t k = 0; k < windows.size(); ++k) {
      still.emplace_back(windows[k].still_from_ns, windows[k].t_start_ns);
      still.emplace_back(windows[k].t_end_ns, windows[k].still_to_ns);
      turns.push_back({windows[k].t_start_ns, windows[k].t_end_ns, out.runs[k].track.end.theta});
    }
    try {
      out.gyro = scan::CalibrateGyro(f.gyro, still, turns);
    } catch (const std::invalid_argument& e) {
      throw InputError(bag.path(), fmt::format("--imu {}: {}", o.imu_topic, e.what()));
    }
    for (std::size_t k = 0; k < windows.size(); ++k) {
      out.runs[k].gyro_heading_change_rad = out.gyro->gyro_heading_change_rad[k];
      const double diff = out.gyro->gyro_heading_change_rad[k] - out.runs[k].track.end.theta;
      if (std::abs(diff) > 0.05)
        warnings.push_back(fmt::format("{}: run {}: the gyro turns {:.4f} rad, the scans {:.4f} rad: check the scan "
                                       "registration (or a gyro that saturates)", bag.path(), run_names[k],
                                       out.gyro->gyro_heading_change_rad[k], out.runs[k].track.end.theta));
    }
  }
  return out;
}

GroundTruthNoise ScanGroundTruthNoise(const std::vector<ScanGroundTruth>& recordings) {
  double sxy = 0.0, sth = 0.0;
  std::size_t runs = 0;
  for (const auto& rec : recordings) {
    for (const auto& r : rec.runs) {
      const auto& c = r.track.end_covariance;
      const double n = static_cast<double>(std::max<std::size_t>(1, std::min(r.track.still_before, r.track.still_after)));
      sxy += std::max(0.25 * (c[0] + c[4]), r.track.still_sd_xy_m * r.track.still_sd_xy_m / n);
      sth += std::max(0.5 * c[8], r.track.still_sd_theta_rad * r.track.still_sd_theta_rad / n);
      ++runs;
    }
  }
  const double n = static_cast<double>(std::max<std::size_t>(1, runs));
  return {std::sqrt(sxy / n), std::sqrt(sth / n)};
}

std::vector<ManifestKey> ScanManifestKeys(const std::vector<ScanGroundTruth>& recordings) {
  std::vector<ManifestKey> keys = {{"source", std::string("scan")}};
  if (!recordings.empty()) {
    const Pose2& m = recordings.front().mount;
    keys.push_back({"scan_pose_x_m", m.x});
    keys.push_back({"scan_pose_y_m", m.y});
    keys.push_back({"scan_pose_yaw_rad", m.theta});
    keys.push_back({"scan_pose_from", recordings.front().mount_source});
  }
  double bias = 0.0, scale = 0.0;
  std::size_t gyros = 0;
  for (const auto& rec : recordings)
    if (rec.gyro) {
      bias += rec.gyro->bias_rad_s;
      scale += rec.gyro->scale;
      ++gyros;
    }
  if (gyros > 0) {
    keys.push_back({"gyro_bias_rad_s", bias / static_cast<double>(gyros)});
    keys.push_back({"gyro_scale", scale / static_cast<double>(gyros)});
  }
  return keys;
}

}  // namespace umbmark::io::rosbag2
