// Ground truth from the lidar and gyro of a recording (see scan_ground_truth.hpp).
#include "ground_truth/scan_ground_truth.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <set>

#include <fmt/format.h>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "ros2/messages.hpp"
#include "ros2/scan_messages.hpp"
#include "scan/mount_check.hpp"
#include "scan/scan_clock.hpp"

namespace umbmark::io::rosbag2 {

namespace {

bool IsBaseFrame(const std::string& f) { return f == "base_link" || f == "base_footprint"; }

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
  StaticTransforms tf;
  std::vector<scan::ScanChange> changes;  // consecutive scans' median range change
  double sweep_s = 0.0;                   // of the first scan
  std::string tf_static_topic;  // the topic read ("" when none)
  bool has_tf_static = false;
  std::string scan_frame;
  std::size_t scans = 0;
  std::vector<scan::GyroSample> gyro;
};

std::string Where(const BagMessage& m, const TopicInfo& t, std::size_t index) {
  return m.offset > 0 ? fmt::format("topic {} ({}), message {} (record at byte {})", t.name, t.type, index, m.offset)
                      : fmt::format("topic {} ({}), message {}", t.name, t.type, index);
}

// The static transform topic: --tf-static, else /tf_static, else the one
// topic named .../tf_static (a namespaced robot: /robot1/tf_static).
std::optional<std::size_t> TfStaticTopic(const Bag& bag, const ScanSourceOptions& o) {
  constexpr const char* kTf = "tf2_msgs/msg/TFMessage";
  if (!o.tf_static_topic.empty()) return RequireTyped(bag, o.tf_static_topic, "--tf-static", kTf);
  if (const auto idx = bag.FindTopic("/tf_static"); idx && bag.topics()[*idx].type == kTf) return idx;
  std::vector<std::size_t> hits;
  for (std::size_t i = 0; i < bag.topics().size(); ++i) {
    const std::string& n = bag.topics()[i].name;
    if (bag.topics()[i].type == kTf && n.size() > 10 && n.compare(n.size() - 10, 10, "/tf_static") == 0) hits.push_back(i);
  }
  if (hits.size() == 1) return hits[0];
  if (hits.size() > 1) {
    std::vector<std::string> names;
    for (std::size_t i : hits) names.push_back(bag.topics()[i].name);
    throw InputError(bag.path(), fmt::format("--scan {}: the recording has no /tf_static but {} static transform topics ({}): "
                                             "name the robot's with --tf-static TOPIC", o.scan_topic, hits.size(),
                                             fmt::join(names, ", ")));
  }
  return std::nullopt;
}

// /tf_static, the gyro and the scan topic's frame and count.
FirstPass ReadFirstPass(const Bag& bag, std::size_t scan_topic, std::optional<std::size_t> imu_topic,
                        const ScanSourceOptions& o) {
  FirstPass f;
  std::vector<bool> wanted(bag.topics().size(), false);
  wanted[scan_topic] = true;
  const auto tf_topic = TfStaticTopic(bag, o);
  if (tf_topic) {
    wanted[*tf_topic] = true;
    f.has_tf_static = true;
    f.tf_static_topic = bag.topics()[*tf_topic].name;
  }
  if (imu_topic) wanted[*imu_topic] = true;
  std::vector<PoseMsg> tf;
  std::size_t imu_index = 0;
  scan::LaserScan prev, cur;
  bag.Read(wanted, [&](const BagMessage& m) {
    const TopicInfo& topic = bag.topics()[m.topic];
    try {
      CdrReader r(m.data, m.size);
      if (m.topic == scan_topic) {
        std::string_view frame;
        DecodeLaserScan(r, cur, frame);
        if (f.scans++ == 0) {
          f.scan_frame = std::string(frame);
          f.sweep_s = std::abs(cur.time_increment) * static_cast<double>(cur.ranges.empty() ? 0 : cur.ranges.size() - 1);
        }
        if (o.log_time) cur.t_ns = m.log_time_ns;
        // The scans' own motion signal, for the clock (scan_clock.hpp).
        if (f.scans > 1 && cur.t_ns > prev.t_ns) {
          const double c = scan::MedianRangeChange(prev, cur);
          if (std::isfinite(c)) f.changes.push_back({prev.t_ns, cur.t_ns, c});
        }
        std::swap(prev, cur);
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
        for (const auto& p : tf) {
          if (!f.tf.Add(p))
            throw InputError(*m.file, fmt::format("{}: the transform {} -> {} is not a rigid transform (quaternion "
                                                  "{}, {}, {}, {}, translation {}, {}, {})", Where(m, topic, 0),
                                                  p.header.frame_id, p.child_frame_id, p.qx, p.qy, p.qz, p.qw, p.x, p.y, p.z));
        }
      }
    } catch (const CdrError& e) {
      throw InputError(*m.file, fmt::format("topic {}: cannot decode: {}", topic.name, e.what()));
    }
  });
  return f;
}

void MountFromTfStatic(const Bag& bag, const FirstPass& f, ScanGroundTruth& out, std::vector<std::string>& warnings) {
  const LidarMount m = *f.tf.Mount(f.scan_frame);
  if (!IsBaseFrame(m.base_frame))
    warnings.push_back(fmt::format("{}: {} reaches no base_link or base_footprint from {}; the lidar pose is "
                                   "taken relative to {}", bag.path(), f.tf_static_topic, f.scan_frame, m.base_frame));
  out.mount = m.pose;
  out.upside_down = m.upside_down;
  if (m.tilt_rad > 0.3)
    warnings.push_back(fmt::format("{}: {}: the lidar's scan plane is tilted {:.1f} deg from the floor ({} -> {}): "
                                   "its ranges to the walls are stretched, check the transform", bag.path(),
                                   f.tf_static_topic, Rad2Deg(m.tilt_rad), m.base_frame, f.scan_frame));
  out.mount_source = fmt::format("{} {} -> {}", f.tf_static_topic == "/tf_static" ? "tf_static" : f.tf_static_topic,
                                 m.base_frame, f.scan_frame);
}

// The lidar's pose in the robot frame: the static transforms up from the
// scan's frame to the first base frame, else --scan-pose, else the origin;
// --scan-upside-down mirrors the beams whatever the source.
void ResolveMount(const Bag& bag, const FirstPass& f, const ScanSourceOptions& o, ScanGroundTruth& out,
                  std::vector<std::string>& warnings) {
  if (IsBaseFrame(f.scan_frame)) {
    out.mount_source = fmt::format("scan frame {} is the robot's base frame", f.scan_frame);
  } else if (f.tf.Mount(f.scan_frame)) {
    MountFromTfStatic(bag, f, out, warnings);
    const Pose2& pose = out.mount;
    if (o.scan_pose && (std::abs(o.scan_pose->x - pose.x) > 1e-3 || std::abs(o.scan_pose->y - pose.y) > 1e-3 ||
                        std::abs(WrapAngle(o.scan_pose->theta - pose.theta)) > 1e-3))
      warnings.push_back(fmt::format("{}: --scan-pose {},{},{} differs from {}'s {},{},{}; {} is used", bag.path(),
                                     o.scan_pose->x, o.scan_pose->y, o.scan_pose->theta, f.tf_static_topic, pose.x, pose.y,
                                     pose.theta, f.tf_static_topic));
    if (o.upside_down && !out.upside_down)
      warnings.push_back(fmt::format("{}: --scan-upside-down: {} has the lidar upright; it is taken as upside down",
                                     bag.path(), f.tf_static_topic));
  } else if (o.scan_pose) {
    out.mount = *o.scan_pose;
    out.mount_source = "--scan-pose";
  } else if (f.has_tf_static && !f.tf.empty()) {
    const std::string frames = f.tf.Describe();
    throw InputError(bag.path(), fmt::format("--scan {}: its frame_id '{}' has no transform in {} ({}) and no "
                                             "--scan-pose X,Y,YAW was given", o.scan_topic, f.scan_frame, f.tf_static_topic,
                                             frames.empty() ? "empty" : frames));
  } else {
    out.mount_source = "origin";
    warnings.push_back(fmt::format("{}: no /tf_static and no --scan-pose: the lidar ({}) is taken to sit at the axle "
                                   "midpoint facing forward", bag.path(), f.scan_frame));
  }
  out.upside_down = out.upside_down || o.upside_down;
  if (out.upside_down) out.mount_source += " (upside down: beams mirrored)";
}

// Streams the scans into one tracker per run; a run's tracker finishes as
// soon as the scans pass its window (its poses are all that is kept).
void TrackScans(const Bag& bag, std::size_t scan_topic, const ScanSourceOptions& o,
                const std::vector<scan::RunWindow>& windows, const std::vector<std::string>& names, const Odometry& odo,
                ScanGroundTruth& out) {
  const std::function<Pose2(std::int64_t)> odometry = [&odo](std::int64_t t) { return odo(t); };
  scan::TrackOptions track = o.track;
  track.mount = out.mount;
  const auto clock_ns = static_cast<std::int64_t>(std::llround(out.clock_coarse_s * 1e9));
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
    if (out.upside_down) scan::MirrorBeams(s);
    if (!(std::isfinite(s.angle_min) && std::isfinite(s.angle_increment) && s.angle_increment != 0.0))
      throw InputError(*m.file, fmt::format("{}: angle_min {} / angle_increment {} is not a usable beam layout",
                                            Where(m, topic, index), s.angle_min, s.angle_increment));
    if (s.t_ns <= prev_t)
      throw InputError(*m.file, fmt::format("{}: stamp {:.9f} s does not increase (previous {:.9f} s){}", Where(m, topic, index),
                                            Seconds(s.t_ns), Seconds(prev_t), o.log_time ? "" : "; try --time log"));
    prev_t = s.t_ns;
    s.t_ns += clock_ns;  // the first ray's time in the wheels' clock
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

// What the still stretches of one run say: the robot moved while its wheels
// stood still (the stretch is split there and only the scans from the run's
// own start or end pose count), too few still scans, or still scans that
// scatter more than a lidar's noise explains.
void StillWarnings(const std::string& path, const ScanSourceOptions& o, const std::string& run, const scan::TrackResult& t,
                   std::vector<std::string>& warnings) {
  auto at = [&](std::int64_t ns) { return fmt::format("t = {:.2f} s", Seconds(ns - o.origin_ns)); };
  if (t.moved_before_ns != 0)
    warnings.push_back(fmt::format("{}: run {}: --scan {}: the robot was moved while its wheels stood still before the run "
                                   "(carried or nudged; the last scan from another pose at {}): only the {} still scans "
                                   "after it ({} .. {}) make the run's start", path, run, o.scan_topic,
                                   at(t.moved_before_ns), t.still_before, at(t.still_before_from_ns), at(t.still_before_to_ns)));
  if (t.moved_after_ns != 0)
    warnings.push_back(fmt::format("{}: run {}: --scan {}: the robot was moved while its wheels stood still after the run "
                                   "(carried or nudged; from {}): only the {} still scans before that ({} .. {}) make the "
                                   "run's end", path, run, o.scan_topic, at(t.moved_after_ns), t.still_after,
                                   at(t.still_after_from_ns), at(t.still_after_to_ns)));
  constexpr std::size_t kFewStill = 3;
  if (t.still_before < kFewStill || t.still_after < kFewStill)
    warnings.push_back(fmt::format("{}: run {}: --scan {}: only {} still scan(s) before and {} after the run: its start and "
                                   "end carry a single scan's noise (2-9 mm, not a fraction of a mm); stand still 3 s or "
                                   "more before and after every run", path, run, o.scan_topic, t.still_before, t.still_after));
  constexpr double kScatterXy = 0.005, kScatterTheta = 0.005;
  if (t.still_sd_xy_m > kScatterXy || t.still_sd_theta_rad > kScatterTheta)
    warnings.push_back(fmt::format("{}: run {}: --scan {}: single still scans scatter by {:.1f} mm and {:.1f} mrad about "
                                   "their average (a still robot's lidar: about 1 mm and 1 mrad): the robot crept or was "
                                   "touched while standing, or the scene moved (people walking past)", path, run,
                                   o.scan_topic, 1e3 * t.still_sd_xy_m, 1e3 * t.still_sd_theta_rad));
}

// Beyond this the stamps are not the scans' times (another computer's
// clock, a simulation clock): refused.
constexpr double kMaxClockOffsetS = 2.0;

// The scan clock's coarse offset from the scans' motion signal against the
// wheels (scan_clock.hpp), before any registration: the still stretches
// around each run depend on it.
void CoarseClock(const std::string& path, const ScanSourceOptions& o, const FirstPass& f,
                 const std::vector<WheelTravel>& wheels, double wheelbase_m, ScanGroundTruth& out) {
  std::vector<std::int64_t> t;
  std::vector<double> l, r;
  for (const auto& w : wheels) {
    t.push_back(w.t_ns);
    l.push_back(w.left_m);
    r.push_back(w.right_m);
  }
  scan::ClockOptions co;
  co.search_s = kMaxClockOffsetS + 1.5;  // an offset beyond the limit is found, and refused
  const scan::ClockEstimate e = scan::EstimateClockCoarse(f.changes, scan::WheelMotion::FromTravel(t, l, r, wheelbase_m), co);
  out.clock_determined = e.determined;
  out.clock_correlation = e.correlation;
  if (!e.determined) return;
  if (std::abs(e.offset_s) > kMaxClockOffsetS)
    throw InputError(path, fmt::format(
        "--scan {}: the scans move {:.2f} s {} the wheels (their stamps {} the wheels' clock; correlation {:.2f} of the "
        "scans' range changes with the wheel motion): beyond {} s the stamps are not the scans' times (a lidar on "
        "another computer, or a simulation clock); record with one clock, or try --time log", o.scan_topic,
        std::abs(e.offset_s), e.offset_s > 0 ? "after" : "before", e.offset_s > 0 ? "lag" : "lead", e.correlation,
        kMaxClockOffsetS));
  out.clock_coarse_s = e.offset_s;
}

// The fine step: the chained headings against the odometry's; their times
// are corrected, and the offset named when it is more than a few ms.
void RefineScanClock(const std::string& path, const ScanSourceOptions& o, const std::vector<scan::RunWindow>& windows,
               const Odometry& odo, ScanGroundTruth& out, std::vector<std::string>& warnings) {
  std::vector<scan::HeadingTrack> tracks(windows.size());
  std::vector<std::int64_t> starts;
  for (std::size_t k = 0; k < windows.size(); ++k) {
    starts.push_back(windows[k].t_start_ns);
    for (const auto& p : out.runs[k].track.poses)
      if (p.t_ns > windows[k].t_start_ns && p.t_ns < windows[k].t_end_ns) {
        tracks[k].t_ns.push_back(p.t_ns);
        tracks[k].scan_heading_rad.push_back(p.pose.theta);
      }
  }
  const scan::FineClock fine = scan::RefineClock(tracks, starts, [&odo](std::int64_t t) { return odo(t).theta; });
  double correction = 0.0;
  if (fine.determined && out.clock_determined) {
    correction = fine.correction_s;
    const auto shift = static_cast<std::int64_t>(std::llround(correction * 1e9));
    for (std::size_t k = 0; k < windows.size(); ++k) {
      auto& poses = out.runs[k].track.poses;
      std::vector<scan::StampedPose> kept;
      for (auto p : poses) {
        const bool chained = p.t_ns > windows[k].t_start_ns && p.t_ns < windows[k].t_end_ns;
        if (chained) p.t_ns += shift;
        if (chained && (p.t_ns <= windows[k].t_start_ns || p.t_ns >= windows[k].t_end_ns)) continue;
        if (kept.empty() || p.t_ns > kept.back().t_ns) kept.push_back(p);
      }
      poses = std::move(kept);
    }
  }
  const double offset = out.clock_coarse_s + correction;
  out.scan_time_offset_s = offset == 0.0 ? 0.0 : -offset;
  if (!out.clock_determined) {
    warnings.push_back(fmt::format("{}: --scan {}: the scan clock could not be checked against the wheels (the scans' "
                                   "range changes follow the wheel motion with a correlation of only {:.2f}): the "
                                   "stamps are taken as the times of the first rays", path, o.scan_topic,
                                   out.clock_correlation));
    return;
  }
  constexpr double kNameOffsetS = 0.01;
  if (std::abs(offset) > kNameOffsetS)
    warnings.push_back(fmt::format("{}: --scan {}: the scans' first rays are {:.3f} s {} their stamps in the wheels' "
                                   "clock (header.stamp minus first ray: {:+.3f} s; estimated against the wheels and "
                                   "corrected){}", path, o.scan_topic, std::abs(offset), offset > 0 ? "after" : "before",
                                   out.scan_time_offset_s,
                                   out.sweep_s > 0.0 && std::abs(out.scan_time_offset_s - out.sweep_s) < 0.02
                                       ? ": the driver stamps the end of the sweep"
                                       : ""));
}

// Stretches of each run (0.2 m or 0.3 rad of wheel motion each) with the
// lidar's registered motion and the wheels' over the same span.
std::vector<scan::MountPair> MountPairs(const std::vector<scan::RunWindow>& windows, const ScanGroundTruth& g,
                                        const Odometry& odo) {
  std::vector<scan::MountPair> pairs;
  for (std::size_t k = 0; k < windows.size(); ++k) {
    const auto& poses = g.runs[k].track.poses;
    const Pose2 a0 = odo(windows[k].t_start_ns);
    std::optional<std::pair<Pose2, Pose2>> from;  // lidar, axle
    for (const auto& p : poses) {
      if (p.t_ns < windows[k].t_start_ns || p.t_ns > windows[k].t_end_ns) continue;
      const Pose2 lidar = scan::LidarMotionFromAxle(g.mount, p.pose), axle = RelativeTo(a0, odo(p.t_ns));
      if (!from) {
        from = {lidar, axle};
        continue;
      }
      const Pose2 da = RelativeTo(from->second, axle);
      if (std::hypot(da.x, da.y) < 0.2 && std::abs(da.theta) < 0.3) continue;
      pairs.push_back({RelativeTo(from->first, lidar), da});
      from = {lidar, axle};
    }
  }
  return pairs;
}

// The run turns of the scans, the wheels and the gyro, for a message.
std::string TurnExample(const ScanGroundTruth& g, const std::vector<scan::RunWindow>& w, const std::vector<std::string>& names,
                        const Odometry& odo) {
  if (w.empty()) return {};
  const double wheels = odo(w[0].t_end_ns).theta - odo(w[0].t_start_ns).theta;
  std::string s = fmt::format("run {}: scans {:+.0f} deg, wheels {:+.0f} deg", names[0], Rad2Deg(g.runs[0].track.end.theta),
                              Rad2Deg(wheels));
  if (g.gyro) s += fmt::format(", gyro {:+.0f} deg", Rad2Deg(g.gyro->gyro_heading_change_rad[0] * g.gyro->scale));
  return s;
}

// The mount against the scans and the wheels (and the gyro): a mirrored
// lidar (upside down) or swapped wheels, a yaw that is not the one used, a
// position far from the one used. Refused: a wrong yaw turns every return
// error, a mirror reverses the turns.
void CheckMount(const std::string& path, const ScanSourceOptions& o, const ScanGroundTruth& g,
                const std::vector<scan::RunWindow>& windows, const std::vector<std::string>& names, const Odometry& odo,
                std::vector<std::string>& warnings) {
  const scan::MountEstimate& e = g.mount_estimate;
  if (e.pairs == 0) return;
  const std::string example = TurnExample(g, windows, names, odo);
  const std::string how = "give the lidar's pose with --scan-pose X,Y,YAW (and --scan-upside-down when it is mounted "
                          "upside down), correct the recording's /tf_static, or estimate the mount with umbmark "
                          "calibrate-lidar";
  if (e.mirrored) {
    const std::string swap = o.left_joint.empty() ? std::string("the wheels are swapped (left for right)")
                                                  : fmt::format("the wheel joints are swapped: run again with --left-joint {} "
                                                                "--right-joint {}", o.right_joint, o.left_joint);
    if (g.gyro && g.gyro->scale > 0.0)
      throw InputError(path, fmt::format("--scan {}: the scans and the gyro turn the other way than the wheels ({}): {}",
                                         o.scan_topic, example, swap));
    if (g.gyro)
      throw InputError(path, fmt::format("--scan {}: the scans turn the other way than the wheels and the gyro ({}): the "
                                         "lidar is mounted upside down (its beam angles run mirrored) and the mount used "
                                         "({}) does not say so; {}", o.scan_topic, example, g.mount_source, how));
    throw InputError(path, fmt::format("--scan {}: the scans turn the other way than the wheels ({}): either the lidar is "
                                       "mounted upside down (its beam angles run mirrored; the mount used, {}, does not say "
                                       "so) or {}; a gyro (--imu TOPIC) tells the two apart. For the lidar: {}",
                                       o.scan_topic, example, g.mount_source, swap, how));
  }
  // The pairs hold the lidar's own motion (the mount used undone), so the
  // estimate is the mount itself.
  const double yaw_error = WrapAngle(e.yaw_rad - g.mount.theta);
  const double x = e.position_determined ? e.x_m : g.mount.x, y = e.position_determined ? e.y_m : g.mount.y;
  constexpr double kMaxYawError = 0.05, kWarnYawError = 0.02, kMaxPositionError = 0.05;
  const double yaw = e.yaw_rad;
  if (std::abs(yaw_error) > kMaxYawError)
    throw InputError(path, fmt::format(
        "--scan {}: the lidar moves {:.1f} deg off the direction the wheels drive: it is mounted at a yaw of about "
        "{:.3f} rad ({:.1f} deg) in the robot frame, not the {:.3f} rad ({:.1f} deg) used ({}); a wrong mount turns every "
        "return error and misplaces every turn. {} (e.g. --scan-pose {:.3f},{:.3f},{:.3f})",
        o.scan_topic, Rad2Deg(yaw_error), WrapAngle(yaw), Rad2Deg(WrapAngle(yaw)), g.mount.theta, Rad2Deg(g.mount.theta),
        g.mount_source, how, x, y, WrapAngle(yaw)));
  if (std::abs(yaw_error) > kWarnYawError)
    warnings.push_back(fmt::format("{}: --scan {}: the scans and the wheels put the lidar's yaw {:.1f} deg from the {:.3f} "
                                   "rad used ({}): check the mount", path, o.scan_topic, Rad2Deg(yaw_error), g.mount.theta,
                                   g.mount_source));
  if (e.position_determined && std::hypot(x - g.mount.x, y - g.mount.y) > kMaxPositionError)
    warnings.push_back(fmt::format("{}: --scan {}: the scans and the wheels put the lidar at about ({:.3f}, {:.3f}) m, "
                                   "{:.0f} mm from the position used ({:.3f}, {:.3f} m, {}): check the mount", path,
                                   o.scan_topic, x, y, 1e3 * std::hypot(x - g.mount.x, y - g.mount.y), g.mount.x, g.mount.y,
                                   g.mount_source));
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
  out.sweep_s = f.sweep_s;
  ResolveMount(bag, f, o, out, warnings);
  const Odometry odo(wheels, wheelbase_m);
  CoarseClock(bag.path(), o, f, wheels, wheelbase_m, out);
  TrackScans(bag, scan_topic, o, windows, run_names, odo, out);
  RefineScanClock(bag.path(), o, windows, odo, out, warnings);
  for (std::size_t k = 0; k < windows.size(); ++k) StillWarnings(bag.path(), o, run_names[k], out.runs[k].track, warnings);
  for (auto& r : out.runs) r.gyro_heading_change_rad = std::numeric_limits<double>::quiet_NaN();
  out.mount_estimate = scan::EstimateMount(MountPairs(windows, out, odo));
  if (imu_topic) {
    std::vector<std::pair<std::int64_t, std::int64_t>> still;
    std::vector<scan::GyroRun> turns;
    // The bias only where the wheels and the scans both say still: the
    // stretches whose scans were averaged (a carry turns the robot while its
    // wheels stand still).
    for (std::size_t k = 0; k < windows.size(); ++k) {
      const scan::TrackResult& t = out.runs[k].track;
      if (t.still_before > 0) still.emplace_back(t.still_before_from_ns, t.still_before_to_ns);
      if (t.still_after > 0) still.emplace_back(t.still_after_from_ns, t.still_after_to_ns);
      turns.push_back({windows[k].t_start_ns, windows[k].t_end_ns, t.end.theta});
    }
    try {
      out.gyro = scan::CalibrateGyro(f.gyro, still, turns);
    } catch (const std::invalid_argument& e) {
      throw InputError(bag.path(), fmt::format("--imu {}: {}", o.imu_topic, e.what()));
    }
  }
  CheckMount(bag.path(), o, out, windows, run_names, odo, warnings);
  if (out.gyro) {
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

std::array<double, 3> StaticTransforms::Rigid3::Rotate(const std::array<double, 3>& v) const {
  const auto& [w, x, y, z] = q;
  const double tx = 2.0 * (y * v[2] - z * v[1]), ty = 2.0 * (z * v[0] - x * v[2]), tz = 2.0 * (x * v[1] - y * v[0]);
  return {v[0] + w * tx + (y * tz - z * ty), v[1] + w * ty + (z * tx - x * tz), v[2] + w * tz + (x * ty - y * tx)};
}

StaticTransforms::Rigid3 StaticTransforms::Rigid3::Then(const Rigid3& o) const {
  const auto& [w1, x1, y1, z1] = q;
  const auto& [w2, x2, y2, z2] = o.q;
  Rigid3 r;
  r.q = {w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2, w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
         w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2};
  const auto ro = Rotate(o.t);
  r.t = {ro[0] + t[0], ro[1] + t[1], ro[2] + t[2]};
  return r;
}

bool StaticTransforms::Add(const PoseMsg& p) {
  const double n = std::sqrt(p.qw * p.qw + p.qx * p.qx + p.qy * p.qy + p.qz * p.qz);
  if (!(n > 0.5 && n < 2.0) || !std::isfinite(p.x + p.y + p.z)) return false;
  tf_[std::string(p.child_frame_id)] = {std::string(p.header.frame_id),
                                        Rigid3{{p.qw / n, p.qx / n, p.qy / n, p.qz / n}, {p.x, p.y, p.z}}};
  return true;
}

std::optional<LidarMount> StaticTransforms::Mount(const std::string& frame) const {
  if (tf_.count(frame) == 0) return std::nullopt;
  Rigid3 chain;
  std::string cur = frame;
  std::set<std::string> seen;
  while (!IsBaseFrame(cur) && tf_.count(cur) > 0 && seen.insert(cur).second) {
    const auto& [parent, t] = tf_.at(cur);
    chain = t.Then(chain);
    cur = parent;
  }
  // The scan plane in the base frame: its x axis gives the yaw; its z axis
  // pointing down (roll or pitch pi) mirrors the beams.
  const auto ex = chain.Rotate({1.0, 0.0, 0.0}), ez = chain.Rotate({0.0, 0.0, 1.0});
  LidarMount m;
  m.pose = {chain.t[0], chain.t[1], std::atan2(ex[1], ex[0])};
  m.upside_down = ez[2] < 0.0;
  m.tilt_rad = std::acos(std::min(1.0, std::abs(ez[2])));
  m.base_frame = cur;
  return m;
}

std::string StaticTransforms::Describe() const {
  std::string frames;
  for (const auto& [child, v] : tf_) frames += (frames.empty() ? "" : ", ") + v.first + " -> " + child;
  return frames;
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
  if (!recordings.empty()) keys.push_back({"scan_time_offset_s", recordings.front().scan_time_offset_s});
  return keys;
}

}  // namespace umbmark::io::rosbag2
