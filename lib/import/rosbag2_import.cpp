// rosbag2 import (see rosbag2_import.hpp and the contract's "ROS 2 recordings").
#include "import/rosbag2_import.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <map>
#include <memory>
#include <set>

#include <fmt/format.h>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "ground_truth/pose_stream.hpp"
#include "ground_truth/source.hpp"
#include "import/wheel_checks.hpp"
#include "ros2/bag_text.hpp"
#include "ros2/messages.hpp"
#include "ros2/tf_tree.hpp"

namespace umbmark::io::rosbag2 {

namespace {

constexpr double kStillM = 1e-6;  // a wheel is still when its travel changes less than this

std::string Lower(std::string_view s) {
  std::string o(s);
  for (char& c : o) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return o;
}

struct StopReading {};

// Resolves the left/right joint indices of a JointState message by name.
class JointPicker {
 public:
  JointPicker(std::string left, std::string right) : left_(std::move(left)), right_(std::move(right)) {}
  // Returns false when a joint is missing; `why` then says what is there.
  bool Pick(const JointStateMsg& m, std::size_t& li, std::size_t& ri, std::string& why) {
    if (Cached(m, li_, resolved_left_) && Cached(m, ri_, resolved_right_)) {
      li = li_;
      ri = ri_;
      return true;
    }
    auto find = [&](const std::string& wanted, const char* side, std::size_t& idx, std::string& resolved) {
      if (!wanted.empty()) {
        for (std::size_t i = 0; i < m.name.size(); ++i)
          if (m.name[i] == wanted) {
            idx = i;
            resolved = wanted;
            return true;
          }
        why = fmt::format("joint '{}' is not in the message; its joints are: {}", wanted, TrimmedList(m.name));
        return false;
      }
      // Names with the side but not the other side ("left_right_arm" is
      // neither wheel); among several, the ones that say "wheel".
      const char* other = std::string_view(side) == "left" ? "right" : "left";
      std::vector<std::size_t> hits, wheels;
      for (std::size_t i = 0; i < m.name.size(); ++i) {
        const std::string n = Lower(m.name[i]);
        if (n.find(side) == std::string::npos || n.find(other) != std::string::npos) continue;
        hits.push_back(i);
        if (n.find("wheel") != std::string::npos) wheels.push_back(i);
      }
      if (hits.size() > 1 && wheels.size() == 1) hits = wheels;
      if (hits.size() != 1) {
        why = fmt::format("{} joint names contain '{}' and not '{}' (joints: {}); name the wheel with --{}-joint",
                          hits.size(), side, other, TrimmedList(m.name), side);
        return false;
      }
      idx = hits[0];
      resolved = std::string(m.name[idx]);
      return true;
    };
    if (!find(left_, "left", li_, resolved_left_) || !find(right_, "right", ri_, resolved_right_)) return false;
    if (li_ == ri_) {
      why = fmt::format("joint '{}' would be both the left and the right wheel; name the two wheel joints with "
                        "--left-joint and --right-joint (joints: {})", resolved_left_, TrimmedList(m.name));
      resolved_left_.clear();
      return false;
    }
    li = li_;
    ri = ri_;
    return true;
  }
  const std::string& left() const { return resolved_left_; }
  const std::string& right() const { return resolved_right_; }

 private:
  static bool Cached(const JointStateMsg& m, std::size_t i, const std::string& name) {
    return !name.empty() && i < m.name.size() && m.name[i] == name;
  }
  std::string left_, right_, resolved_left_, resolved_right_;
  std::size_t li_ = 0, ri_ = 0;
};

// Turns the Odometry poses (x, y in left/right, yaw) into cumulative wheel
// travel: the inverse of DiffDriveStep (diff_drive.hpp). Per step, with
// dtheta = wrap(yaw_k - yaw_k-1) and the displacement projected on the
// heading yaw_k-1 + dtheta/2: ds = projection (midpoint) or projection /
// sinc(dtheta/2) (arc); dR = ds + b dtheta/2, dL = ds - b dtheta/2.
void OdometryToWheels(std::vector<WheelSample>& s, double wheelbase, Integrator integ) {
  double cl = 0.0, cr = 0.0;
  double px = s.empty() ? 0.0 : s[0].left, py = s.empty() ? 0.0 : s[0].right, pyaw = s.empty() ? 0.0 : s[0].yaw;
  for (std::size_t k = 0; k < s.size(); ++k) {
    const double x = s[k].left, y = s[k].right, yaw = s[k].yaw;
    if (k > 0) {
      const double dth = WrapAngle(yaw - pyaw);
      const double heading = pyaw + 0.5 * dth;
      const double proj = (x - px) * std::cos(heading) + (y - py) * std::sin(heading);
      const double ds = integ == Integrator::kArc ? proj / Sinc(0.5 * dth) : proj;
      cr += ds + 0.5 * wheelbase * dth;
      cl += ds - 0.5 * wheelbase * dth;
    }
    px = x;
    py = y;
    pyaw = yaw;
    s[k].left = cl;
    s[k].right = cr;
  }
}

// [first, last] sample index pairs of the runs, split at pauses (contract:
// "Runs").
std::vector<std::pair<std::size_t, std::size_t>> SplitRuns(const std::vector<WheelSample>& s, double pause_s) {
  std::vector<std::pair<std::size_t, std::size_t>> runs;
  if (s.size() < 2) return runs;
  if (pause_s <= 0.0) return {{0, s.size() - 1}};
  std::vector<std::pair<std::size_t, std::size_t>> pauses;  // [a, b]: every interval a..b still
  std::size_t k = 1;
  while (k < s.size()) {
    auto still = [&](std::size_t i) {
      return std::abs(s[i].left - s[i - 1].left) < kStillM && std::abs(s[i].right - s[i - 1].right) < kStillM;
    };
    if (!still(k)) {
      ++k;
      continue;
    }
    const std::size_t a = k - 1;
    while (k < s.size() && still(k)) ++k;
    const std::size_t b = k - 1;
    if (static_cast<double>(s[b].t_ns - s[a].t_ns) * 1e-9 >= pause_s) pauses.emplace_back(a, b);
  }
  std::size_t start = 0;
  bool open = true;  // a run may begin at sample 0 (no leading pause)
  for (const auto& [a, b] : pauses) {
    if (open && a > start) runs.emplace_back(start, a);
    start = b;
    open = true;
  }
  if (start < s.size() - 1) runs.emplace_back(start, s.size() - 1);
  return runs;
}

// Linear interpolation of ground truth at time t (x, y, unwrapped yaw), or
// NaN when no sample lies within max_gap on both sides. `j` may start
// anywhere (the result does not depend on it): Start puts it at t.
struct GtInterpolator {
  const std::vector<GroundTruthSample>& gt;
  std::int64_t max_gap_ns;
  std::size_t j = 0;
  void Start(std::int64_t t) {
    const auto it = std::upper_bound(gt.begin(), gt.end(), t, [](std::int64_t v, const GroundTruthSample& g) { return v < g.t_ns; });
    j = it == gt.begin() ? 0 : static_cast<std::size_t>(it - gt.begin()) - 1;
  }
  Pose2 At(std::int64_t t) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    if (gt.empty() || t < gt.front().t_ns || t > gt.back().t_ns) return {nan, nan, nan};
    while (j + 1 < gt.size() && gt[j + 1].t_ns <= t) ++j;
    while (j > 0 && gt[j].t_ns > t) --j;
    const GroundTruthSample& a = gt[j];
    if (a.t_ns == t) return {a.x, a.y, a.yaw};
    const GroundTruthSample& b = gt[j + 1];
    if (t - a.t_ns > max_gap_ns || b.t_ns - t > max_gap_ns) return {nan, nan, nan};
    const double u = static_cast<double>(t - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns);
    return {a.x + u * (b.x - a.x), a.y + u * (b.y - a.y), a.yaw + u * (b.yaw - a.yaw)};
  }
};

struct TopicChoice {
  std::size_t wheels = 0;
  std::vector<bool> source_topics;  ///< the topics the ground-truth source decodes in the pass
};

TopicChoice ChooseTopics(const Bag& bag, const Rosbag2ImportOptions& o, GroundTruthSource* source) {
  TopicChoice c;
  const bool joints = !o.wheels_topic.empty();
  c.wheels = RequireTopic(bag, joints ? o.wheels_topic : o.odometry_topic, joints ? "--wheels" : "--odometry");
  const TopicInfo& w = bag.topics()[c.wheels];
  const MessageType wt = MessageTypeFromName(w.type);
  if (joints && wt != MessageType::kJointState)
    throw InputError(bag.path(), fmt::format("--wheels topic {} has type {}; it must be sensor_msgs/msg/JointState{}",
                                             w.name, w.type, wt == MessageType::kOdometry ? " (use --odometry for nav_msgs/msg/Odometry)" : ""));
  if (!joints && wt != MessageType::kOdometry)
    throw InputError(bag.path(), fmt::format("--odometry topic {} has type {}; it must be nav_msgs/msg/Odometry{}", w.name,
                                             w.type, wt == MessageType::kJointState ? " (use --wheels for JointState)" : ""));
  c.source_topics.assign(bag.topics().size(), false);
  if (source)
    for (std::size_t t : source->Open(bag, c.wheels)) c.source_topics[t] = true;
  return c;
}

struct RecordingData {
  std::vector<WheelSample> wheels;
  std::string left_joint, right_joint;
  /// header stamp minus receive time [s] of every wheel message
  std::vector<double> wheel_lag_s;
  std::size_t wheel_duplicates = 0;
  std::string odom_frame;       ///< --odometry: its header.frame_id
};

// One streaming pass over the recording: decodes the wheel topic into
// time-stamped samples (the only per-message state kept) and hands the
// ground-truth source's topics to it.
class RecordingReader {
 public:
  RecordingReader(const Bag& bag, const TopicChoice& c, const Rosbag2ImportOptions& o, RecordingData& d,
                  GroundTruthSource* source)
      : bag_(bag), c_(c), o_(o), d_(d), source_(source), picker_(o.left_joint, o.right_joint) {}

  void Read() {
    std::vector<bool> wanted = c_.source_topics;
    wanted[c_.wheels] = true;
    bag_.Read(wanted, [&](const BagMessage& m) {
      const TopicInfo& topic = bag_.topics()[m.topic];
      const std::size_t index = m.topic == c_.wheels ? ++wheel_index_ : ++gt_index_;
      try {
        CdrReader r(m.data, m.size);
        if (m.topic == c_.wheels) OnWheels(r, m, topic, index);
        else source_->OnMessage(r, m, topic, index);
      } catch (const CdrError& e) {
        throw InputError(*m.file, fmt::format("{}: cannot decode: {}", WhereInBag(m, topic, index), e.what()));
      }
    });
    d_.left_joint = picker_.left();
    d_.right_joint = picker_.right();
  }

 private:
  void OnWheels(CdrReader& r, const BagMessage& m, const TopicInfo& topic, std::size_t index) {
    WheelSample s{};
    s.msg = index;
    std::int64_t stamp;
    if (!o_.wheels_topic.empty()) {
      DecodeJointState(r, js_);
      std::size_t li = 0, ri = 0;
      std::string why;
      if (!picker_.Pick(js_, li, ri, why)) throw InputError(*m.file, fmt::format("{}: {}", WhereInBag(m, topic, index), why));
      if (js_.position.empty() && js_.velocity_count > 0)
        throw InputError(*m.file, fmt::format(
            "{}: this JointState carries velocity[] but no position[], so the wheel travel is not in it (integrating "
            "velocities would add their noise and latency to the calibration); give the robot's nav_msgs/msg/Odometry "
            "topic with --odometry TOPIC instead (--list shows it), or record the joint positions",
            WhereInBag(m, topic, index)));
      if (js_.position.size() != js_.name.size())
        throw InputError(*m.file, fmt::format("{}: {} joint names but {} positions", WhereInBag(m, topic, index),
                                              js_.name.size(), js_.position.size()));
      s.left = js_.position[li];  // radians until SanitizeJointPositions
      s.right = js_.position[ri];
      if (!std::isfinite(s.left) || !std::isfinite(s.right))
        throw InputError(*m.file, fmt::format("{}: wheel position is not finite", WhereInBag(m, topic, index)));
      stamp = js_.header.stamp_ns;
    } else {
      const PoseMsg p = DecodeOdometry(r);
      CheckPoseFinite(p, m, topic, index);
      s.left = p.x;
      s.right = p.y;
      s.yaw = p.Yaw();
      stamp = p.header.stamp_ns;
      if (d_.odom_frame.empty()) d_.odom_frame = std::string(p.header.frame_id);
    }
    s.t_ns = o_.time == StampSource::kHeader ? stamp : m.log_time_ns;
    if (!d_.wheels.empty() && s.t_ns <= d_.wheels.back().t_ns) {
      const WheelSample& b = d_.wheels.back();
      const bool same = b.left == s.left && b.right == s.right && b.yaw == s.yaw;
      if (s.t_ns < b.t_ns || !same) StampGoesBack(b.t_ns, s.t_ns, m, topic, index, o_.time == StampSource::kLog, same);
      ++d_.wheel_duplicates;  // a repeated message: harmless, dropped
      return;
    }
    d_.wheel_lag_s.push_back(static_cast<double>(stamp - m.log_time_ns) * 1e-9);
    d_.wheels.push_back(s);
  }

  const Bag& bag_;
  const TopicChoice& c_;
  const Rosbag2ImportOptions& o_;
  RecordingData& d_;
  GroundTruthSource* source_;
  JointPicker picker_;
  JointStateMsg js_;
  std::size_t wheel_index_ = 0, gt_index_ = 0;
};

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// The two streams' clocks, compared through the recording's receive times:
// a motion-capture PC whose clock is off shows as header stamps far from
// the receive times on one topic only.
void CheckClockOffset(const Bag& bag, const TopicChoice& c, const Rosbag2ImportOptions& o, const RecordingData& d,
                      const GroundTruthSource* source) {
  const std::optional<StampLag> lag = source ? source->Lag() : std::nullopt;
  if (!lag) return;
  const double wheel_lag = Median(d.wheel_lag_s), gt_lag = lag->median_s;
  const double ow = o.time == StampSource::kHeader ? wheel_lag : 0.0;
  const double og = o.GroundTruthTime() == StampSource::kHeader ? gt_lag : 0.0;
  const double offset = og - ow;
  if (std::abs(offset) <= 0.5) return;
  const std::string& wt = bag.topics()[c.wheels].name;
  const std::string& gt = lag->topic;
  throw InputError(bag.path(), fmt::format(
      "the ground truth's clock is {:.3f} s {} the wheels' (--time {},{}): header stamps minus receive times are {:.3f} s "
      "on {} and {:.3f} s on {} (median), so the two topics were stamped by clocks {:.1f} s apart (a motion-capture "
      "computer not synchronised with the robot?). Take the receive time for the stream whose clock is off: --time "
      "{}, or --time log for both",
      std::abs(offset), offset > 0 ? "ahead of" : "behind", o.time == StampSource::kHeader ? "header" : "log",
      o.GroundTruthTime() == StampSource::kHeader ? "header" : "log", gt_lag, gt, wheel_lag, wt, std::abs(offset),
      std::abs(gt_lag) > std::abs(wheel_lag) ? "header,log" : "log,header"));
}

// Reads the recording, then the checks that need all of it: clocks, the
// transform tree, the wheel positions (unwrap, resets, jumps, stuck or
// shared joints), and converts the wheel source to travel in metres.
RecordingData ReadRecording(const Bag& bag, const TopicChoice& c, const RobotParams& robot, const Rosbag2ImportOptions& o,
                            GroundTruthSource* source, std::vector<std::string>& warnings) {
  RecordingData d;
  const TopicInfo& wt = bag.topics()[c.wheels];
  const bool joints = !o.wheels_topic.empty();
  RecordingReader reader(bag, c, o, d, source);
  reader.Read();
  if (d.wheels.size() < 2)
    throw InputError(bag.path(), fmt::format("wheel topic {} has {} message(s); at least two are needed", wt.name, d.wheels.size()));
  if (d.wheel_duplicates > 0)
    warnings.push_back(fmt::format("{}: topic {}: {} message(s) repeat the previous message's stamp and values; dropped",
                                   bag.path(), wt.name, d.wheel_duplicates));
  if (source) source->EndOfPass(bag, d.odom_frame, warnings);
  CheckClockOffset(bag, c, o, d, source);
  const WheelContext ctx{bag.path(), wt.name, joints ? d.left_joint : "left wheel", joints ? d.right_joint : "right wheel",
                         !joints};
  if (joints) {
    SanitizeJointPositions(d.wheels, ctx, warnings);
    const double rl = 0.5 * robot.wheel_diameter_left_m, rr = 0.5 * robot.wheel_diameter_right_m;
    for (auto& s : d.wheels) {
      s.left *= rl;
      s.right *= rr;
    }
  } else {
    // A controller restart puts the pose back at the origin.
    std::vector<bool> at_origin(d.wheels.size());
    for (std::size_t k = 0; k < d.wheels.size(); ++k)
      at_origin[k] = std::hypot(d.wheels[k].left, d.wheels[k].right) < 0.05 && std::abs(d.wheels[k].yaw) < 0.1;
    OdometryToWheels(d.wheels, robot.wheelbase_m, o.integrator);
    SanitizeOdometryTravel(d.wheels, at_origin, ctx, warnings);
  }
  CheckStuckWheel(d.wheels, ctx);
  return d;
}

}  // namespace

std::string Rosbag2ImportOptions::Validate() const {
  if (wheels_topic.empty() == odometry_topic.empty()) return "exactly one wheel source is needed: --wheels TOPIC or --odometry TOPIC";
  if (!odometry_topic.empty() && (!left_joint.empty() || !right_joint.empty()))
    return "--left-joint/--right-joint apply to --wheels (JointState), not to --odometry";
  if (!left_joint.empty() && left_joint == right_joint)
    return fmt::format("left_joint = right_joint = '{}': --left-joint and --right-joint must name two different wheel joints",
                       left_joint);
  if (kind == ExperimentKind::kSquare && !(side_m > 0.0 && std::isfinite(side_m)))
    return fmt::format("side_m = {}: a square experiment needs --side > 0", side_m);
  if (kind == ExperimentKind::kBackAndForth && !(distance_m > 0.0 && std::isfinite(distance_m)))
    return fmt::format("distance_m = {}: a back_and_forth experiment needs --distance > 0", distance_m);
  if (!(pause_s >= 0.0) || !std::isfinite(pause_s)) return fmt::format("pause_s = {}: must be >= 0", pause_s);
  if (!(max_gt_gap_s > 0.0) || !std::isfinite(max_gt_gap_s)) return fmt::format("max_gt_gap_s = {}: must be > 0", max_gt_gap_s);
  if (!ground_truth_frame.empty() && ground_truth_topic.empty()) return "--ground-truth-frame needs --ground-truth";
  if (!scan_topic.empty() && !ground_truth_topic.empty()) return "--scan and --ground-truth are two ground truths: give one";
  if (scan_topic.empty() && (!imu_topic.empty() || scan_pose || !tf_static_topic.empty() || scan_upside_down))
    return fmt::format("{} needs --scan", !imu_topic.empty() ? "--imu"
                                          : scan_pose         ? "--scan-pose"
                                          : scan_upside_down  ? "--scan-upside-down"
                                                              : "--tf-static");
  if (scan_pose && !(std::isfinite(scan_pose->x) && std::isfinite(scan_pose->y) && std::isfinite(scan_pose->theta)))
    return "scan_pose: --scan-pose X,Y,YAW must be finite";
  return {};
}

namespace {

// One run from samples a..b: travel relative to its first sample, ground
// truth re-expressed in the frame of its first ground-truth sample, and
// `turn` the ground truth's total rotation (NaN without ground truth).
TrajectoryRun BuildRun(const RecordingData& d, std::size_t a, std::size_t b, const RunGroundTruth* gt, double& turn) {
  TrajectoryRun run;
  const bool has_gt = gt != nullptr;
  static const std::vector<GroundTruthSample> kNone;
  GtInterpolator interp{gt ? *gt->samples : kNone, gt ? gt->max_gap_ns : 0};
  interp.Start(d.wheels[a].t_ns);
  std::optional<Pose2> origin;
  double gt_first_yaw = 0.0, gt_last_yaw = 0.0;
  const std::int64_t t0 = d.wheels.front().t_ns;
  for (std::size_t i = a; i <= b; ++i) {
    const WheelSample& s = d.wheels[i];
    run.t_s.push_back(static_cast<double>(s.t_ns - t0) * 1e-9);
    run.dist_left_m.push_back(s.left - d.wheels[a].left);
    run.dist_right_m.push_back(s.right - d.wheels[a].right);
    Pose2 g = has_gt ? interp.At(s.t_ns) : Pose2{NAN, NAN, NAN};
    if (!std::isnan(g.x)) {
      if (!origin) {
        origin = g;
        gt_first_yaw = g.theta;
      }
      gt_last_yaw = g.theta;
      g = RelativeTo(*origin, g);
    }
    run.gt_x_m.push_back(g.x);
    run.gt_y_m.push_back(g.y);
    run.gt_theta_rad.push_back(g.theta);
    run.lines.push_back(0);
  }
  turn = origin ? gt_last_yaw - gt_first_yaw : NAN;
  return run;
}

// In a square both wheels drive forward on every leg: a joint whose travel
// is negative while the other's is positive runs backwards (its joint axis
// points the other way), which is neither a swap nor a turn, and is said so.
void CheckWheelsForward(const TrajectoryRun& run, const Rosbag2ImportOptions& o, const std::string& path,
                        const RecordingData& d) {
  if (o.kind != ExperimentKind::kSquare || o.wheels_topic.empty()) return;
  const double l = run.dist_left_m.back(), r = run.dist_right_m.back();
  if ((l > 0) == (r > 0) || std::min(std::abs(l), std::abs(r)) < o.side_m) return;
  const bool left_back = l < 0;
  throw InputError(path, fmt::format(
      "run {}: joint {} travels {:+.3f} m while joint {} travels {:+.3f} m around a {} m square: the position of {} falls "
      "while the robot drives forward (its joint axis points the other way); umbmark takes wheel positions that grow "
      "when the robot drives forward: import the controller's nav_msgs/msg/Odometry with --odometry instead",
      run.run, left_back ? d.left_joint : d.right_joint, left_back ? l : r, left_back ? d.right_joint : d.left_joint,
      left_back ? r : l, o.side_m, left_back ? d.left_joint : d.right_joint));
}

// Ground truth against dead reckoning from the wheel travel (robot file,
// integrator) along one run. It "follows" the odometry when it matches to
// 1e-4 of the path, or when it differs by its own noise only: the heading
// residual does not drift (mean over the last tenth of the run minus the
// first tenth's within 4 standard errors, the noise taken from consecutive
// differences) and no position residual exceeds 10 times its noise. Real
// ground truth sees the odometry drift: mrad in heading, mm to cm in position.
struct OdometryMatch {
  bool compared = false, follows = false;
  double dev = 0.0, path = 0.0;
};
OdometryMatch CompareWithOdometry(const TrajectoryRun& run, const RobotParams& robot, Integrator integrator) {
  OdometryMatch m;
  std::vector<std::array<double, 3>> res;  // x, y, heading residuals
  Pose2 p;
  for (std::size_t i = 0; i < run.size(); ++i) {
    if (i > 0) {
      const double dl = run.dist_left_m[i] - run.dist_left_m[i - 1], dr = run.dist_right_m[i] - run.dist_right_m[i - 1];
      p = DiffDriveStep(p, dl, dr, robot.wheelbase_m, integrator);
      m.path += 0.5 * (std::abs(dl) + std::abs(dr));
    }
    if (!run.HasGroundTruth(i)) return m;
    res.push_back({run.gt_x_m[i] - p.x, run.gt_y_m[i] - p.y, run.gt_theta_rad[i] - p.theta});
    m.dev = std::max({m.dev, std::hypot(res.back()[0], res.back()[1]), std::abs(res.back()[2])});
  }
  if (m.path < 0.5 || res.size() < 40) return m;
  m.compared = true;
  if (m.dev < 1e-4 * m.path) {
    m.follows = true;
    return m;
  }
  const std::size_t n = res.size(), w = n / 10;
  std::array<double, 3> sigma{}, first{}, last{};
  for (std::size_t c = 0; c < 3; ++c) {
    for (std::size_t i = 1; i < n; ++i) sigma[c] += (res[i][c] - res[i - 1][c]) * (res[i][c] - res[i - 1][c]);
    sigma[c] = std::sqrt(sigma[c] / (2.0 * static_cast<double>(n - 1)));
    for (std::size_t i = 0; i < w; ++i) {
      first[c] += res[i][c] / static_cast<double>(w);
      last[c] += res[n - w + i][c] / static_cast<double>(w);
    }
  }
  const bool heading_still = std::abs(last[2] - first[2]) < 4.0 * sigma[2] * std::sqrt(2.0 / static_cast<double>(w));
  double pos_dev = 0.0;
  for (const auto& r : res) pos_dev = std::max(pos_dev, std::hypot(r[0], r[1]));
  m.follows = heading_still && pos_dev < 10.0 * std::hypot(sigma[0], sigma[1]);
  return m;
}

// What the ground truth says against the wheels, over a recording's runs:
// wheels turning the other way than the ground truth in most runs (the
// joints swapped), and ground truth that is the wheel odometry itself.
void CheckAgainstGroundTruth(const std::vector<TrajectoryRun>& runs, const std::vector<double>& turns,
                             const RobotParams& robot, const Rosbag2ImportOptions& o, const std::string& path,
                             const RecordingData& d, const GroundTruthSource& source) {
  std::size_t mirrored = 0, compared = 0, matching = 0;
  std::string example;
  double worst = 0.0, path_m = 0.0;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const TrajectoryRun& run = runs[r];
    const double odo = (run.dist_right_m.back() - run.dist_left_m.back()) / robot.wheelbase_m;
    if (std::isfinite(turns[r]) && std::abs(turns[r]) > kPi && std::abs(odo) > kPi && (odo > 0) != (turns[r] > 0)) {
      if (mirrored++ == 0)
        example = fmt::format("run {}: wheels {:+.0f} deg, ground truth {:+.0f} deg", run.run, Rad2Deg(odo), Rad2Deg(turns[r]));
    }
    const OdometryMatch m = CompareWithOdometry(run, robot, o.integrator);
    if (!m.compared) continue;
    ++compared;
    if (m.follows) ++matching;
    worst = std::max(worst, m.dev);
    path_m += m.path;
  }
  if (mirrored > 0 && 2 * mirrored > runs.size() && !o.wheels_topic.empty()) {
    throw InputError(path, fmt::format(
        "in {} of {} runs the wheels turn the other way than the ground truth ({}): the left and right wheel joints are "
        "swapped; run again with --left-joint {} --right-joint {}",
        mirrored, runs.size(), example, d.right_joint, d.left_joint));
  }
  if (compared > 0 && matching == compared) {
    throw InputError(path, fmt::format(
        "{} follows the wheel odometry to within {:.2g} m / rad, or its own noise, over {} run(s) and "
        "{:.1f} m: it is the robot's own odometry (an odom frame, or an odometry topic), not an independent measurement, and would only "
        "compare the odometry with itself; choose the motion-capture topic or frame (--list)",
        source.Name(), worst, compared, path_m));
  }
}

// A square's legs as the wheels measured them: the run's mean wheel travel
// over four (spot turns add none). A --side that the odometry contradicts
// (more than 15 % off: a wheel scale is off by 1-3 %, rounded corners by a
// few %) would scale E_d's and E_b's geometry wrongly; refused.
void CheckSideAgainstLegs(const std::vector<TrajectoryRun>& runs, const Rosbag2ImportOptions& o, const std::string& path) {
  if (o.kind != ExperimentKind::kSquare || runs.empty()) return;
  std::vector<double> legs;
  for (const auto& r : runs) legs.push_back(0.25 * 0.5 * (std::abs(r.dist_left_m.back()) + std::abs(r.dist_right_m.back())));
  std::nth_element(legs.begin(), legs.begin() + static_cast<std::ptrdiff_t>(legs.size() / 2), legs.end());
  const double leg = legs[legs.size() / 2];
  constexpr double kMaxSideError = 0.15;
  if (std::abs(leg / o.side_m - 1.0) <= kMaxSideError) return;
  throw InputError(path, fmt::format("--side {} m, but the wheels drive legs of {:.3f} m (median over {} run(s): the mean "
                                     "wheel travel of a run over 4): the squares were {:.2f} m, not {} m; give the side "
                                     "the robot drove (--side {:.2f}), or check the robot file's wheel diameters",
                                     o.side_m, leg, runs.size(), leg, o.side_m, leg));
}

// The ground-truth source's options from the import's.
GroundTruthOptions GroundTruthOptionsOf(const Rosbag2ImportOptions& o) {
  GroundTruthOptions g;
  g.source = o.ground_truth_source;
  g.topic = o.ground_truth_topic;
  g.frame = o.ground_truth_frame;
  g.scan_topic = o.scan_topic;
  g.imu_topic = o.imu_topic;
  g.scan_pose = o.scan_pose;
  g.tf_static_topic = o.tf_static_topic;
  g.scan_upside_down = o.scan_upside_down;
  g.log_time = o.GroundTruthTime() == StampSource::kLog;
  g.max_gap_s = o.max_gt_gap_s;
  return g;
}

// The recording's runs as a ground-truth source sees them.
RecordingRuns RunsOf(const RecordingData& d, const std::vector<std::pair<std::size_t, std::size_t>>& spans,
                     std::size_t first_run, const RobotParams& robot) {
  RecordingRuns r;
  r.wheels.reserve(d.wheels.size());
  for (const auto& w : d.wheels) r.wheels.push_back({w.t_ns, w.left, w.right});
  r.spans = spans;
  r.first_run = first_run;
  r.wheelbase_m = robot.wheelbase_m;
  r.left_joint = d.left_joint;
  r.right_joint = d.right_joint;
  return r;
}

}  // namespace

// Per recording: read, split, drop runs with a gap in the wheel topic, then
// build each run and label its direction; kept in one function so the
// contract's run rules read in one place.
Rosbag2Import ImportRosbag2(const std::vector<std::string>& bags, const RobotParams& robot,
                            const Rosbag2ImportOptions& o) {
  if (const std::string err = o.Validate(); !err.empty()) throw InvalidOptions(err);
  if (const std::string err = robot.Check(); !err.empty()) throw InvalidOptions("robot parameters: " + err);
  Rosbag2Import out;
  out.experiment.kind = o.kind;
  out.experiment.side_m = o.kind == ExperimentKind::kSquare ? o.side_m : 0.0;
  out.experiment.distance_m = o.kind == ExperimentKind::kBackAndForth ? o.distance_m : 0.0;
  out.experiment.file = "runs.csv";
  out.runs.path = "runs.csv";
  // The ground truth, whichever source gives it (ground_truth/source.hpp).
  const std::unique_ptr<GroundTruthSource> source = MakeGroundTruthSource(GroundTruthOptionsOf(o));
  for (const auto& path : bags) {
    const Bag bag = Bag::Open(path, out.warnings);
    const TopicChoice choice = ChooseTopics(bag, o, source.get());
    const RecordingData d = ReadRecording(bag, choice, robot, o, source.get(), out.warnings);
    const std::string& wheel_topic = bag.topics()[choice.wheels].name;
    RecordingSummary rs{path, d.wheels.size(), 0, 0, 0, d.left_joint, d.right_joint,
                        static_cast<double>(d.wheels.back().t_ns - d.wheels.front().t_ns) * 1e-9};
    rs.first_stamp_ns = d.wheels.front().t_ns;
    const auto spans = SplitRuns(d.wheels, o.pause_s);
    if (spans.empty())
      throw InputError(path, fmt::format("the wheels never move on {} ({} samples): no run to import", wheel_topic,
                                         d.wheels.size()));
    const auto gaps = FindGaps(d.wheels);
    if (source) source->ReadRuns(bag, RunsOf(d, spans, out.runs.runs.size(), robot), out.warnings);
    std::vector<TrajectoryRun> runs;
    std::vector<double> turns;
    for (std::size_t k = 0; k < spans.size(); ++k) {
      const std::size_t a = spans[k].first, b = spans[k].second;
      const auto gap = std::find_if(gaps.begin(), gaps.end(), [a, b](const WheelGap& g) { return g.k > a && g.k <= b; });
      if (gap != gaps.end()) {
        ++rs.runs_dropped;
        out.warnings.push_back(fmt::format(
            "{}: topic {} has no message for {:.2f} s (usually every {:.3f} s) at stamp {} while the wheels moved {:.3f} m, "
            "inside the run of t = {:.2f} .. {:.2f} s: the path over the gap is unknown, so that run is dropped",
            path, wheel_topic, gap->seconds, gap->typical_s, StampText(d.wheels[gap->k - 1].t_ns), gap->travel_m,
            static_cast<double>(d.wheels[a].t_ns - d.wheels.front().t_ns) * 1e-9,
            static_cast<double>(d.wheels[b].t_ns - d.wheels.front().t_ns) * 1e-9));
        continue;
      }
      double turn = NAN;
      const std::optional<RunGroundTruth> gt = source ? std::optional(source->Run(k)) : std::nullopt;
      TrajectoryRun run = BuildRun(d, a, b, gt ? &*gt : nullptr, turn);
      run.run = std::to_string(out.runs.runs.size() + runs.size() + 1);
      CheckWheelsForward(run, o, path, d);
      if (source && !run.HasGroundTruth(0))
        out.warnings.push_back(fmt::format("{}: run {} has no ground truth within {} s of its first sample; its ground truth "
                                           "is relative to its first measured pose", path, run.run, o.max_gt_gap_s));
      if (o.kind == ExperimentKind::kSquare) {
        // Direction from the total rotation: ground truth, or odometry without it.
        const bool from_gt = std::isfinite(turn);
        const double total = from_gt ? turn : ((run.dist_right_m.back() - run.dist_left_m.back()) / robot.wheelbase_m);
        if (std::abs(std::abs(total) - 2.0 * kPi) > kPi / 2.0) {
          throw InputError(path, fmt::format("run {} (t = {:.2f} .. {:.2f} s) turns {:.1f} deg in total by its {}; a square run "
                                             "turns about +-360 deg (check --pause, now {} s, and the topics)",
                                             run.run, run.t_s.front(), run.t_s.back(), Rad2Deg(total),
                                             from_gt ? "ground truth" : "odometry", o.pause_s));
        }
        run.direction = total < 0.0 ? "cw" : "ccw";
      } else {
        run.direction = ExperimentKindToString(o.kind);
      }
      runs.push_back(std::move(run));
      turns.push_back(turn);
    }
    if (runs.empty())
      throw InputError(path, fmt::format("every run of {} has a gap in {} (see the warnings above): no run to import", path,
                                         wheel_topic));
    if (source && source->CheckAgainstOdometry()) CheckAgainstGroundTruth(runs, turns, robot, o, path, d, *source);
    CheckSideAgainstLegs(runs, o, path);
    rs.runs = runs.size();
    for (auto& r : runs) out.runs.runs.push_back(std::move(r));
    if (source) {
      rs.ground_truth_messages = source->Messages();
      source->EndRecording();
    }
    out.recordings.push_back(rs);
  }
  if (source) {
    GroundTruthExtras x = source->Finish();
    out.ground_truth = x.noise;
    out.ground_truth_keys = std::move(x.manifest_keys);
    out.scan = std::move(x.scan);
  }
  return out;
}

namespace {

// A latched static transform topic: /tf_static or a namespaced .../tf_static.
bool IsStaticTopic(const std::string& name) {
  return name == "/tf_static" || (name.size() > 10 && name.compare(name.size() - 10, 10, "/tf_static") == 0);
}

// REP 105's odometry frame (odom, or a namespaced robot1/odom): an Odometry
// in it is the robot's own dead reckoning, never ground truth.
bool IsOdometryFrame(const std::string& frame) {
  const std::string f = Lower(frame);
  return f == "odom" || (f.size() > 5 && (f.compare(f.size() - 5, 5, "/odom") == 0 || f.compare(f.size() - 5, 5, "_odom") == 0));
}

}  // namespace

// Joint names from the first message of each JointState topic; the whole
// of each TFMessage topic (every frame with its parent and rate: a frame
// may first appear late). Stops as soon as only JointState topics were
// wanted and each has given its first message. Long (about 90 lines) because
// every listed type (joints, frames, a lidar's frame and mount, an
// odometry frame) is filled in by the one read callback, in one pass.
BagListing ListRosbag2(const std::string& path, std::vector<std::string>& warnings) {
  const Bag bag = Bag::Open(path, warnings);
  BagListing out{path, bag.files(), {}};
  std::vector<bool> wanted(bag.topics().size(), false);
  std::size_t pending = 0;
  bool whole = false;
  for (std::size_t i = 0; i < bag.topics().size(); ++i) {
    TopicListing l;
    l.topic = bag.topics()[i];
    const MessageType t = MessageTypeFromName(l.topic.type);
    l.wheels = t == MessageType::kJointState || t == MessageType::kOdometry;
    l.ground_truth = IsPoseType(t);
    l.scan = l.topic.type == "sensor_msgs/msg/LaserScan";
    l.imu = l.topic.type == "sensor_msgs/msg/Imu";
    l.static_transforms = t == MessageType::kTfMessage && IsStaticTopic(l.topic.name);
    if ((t == MessageType::kJointState || IsPoseType(t) || l.scan) && l.topic.count > 0 &&
        l.topic.serialization_format == "cdr") {
      wanted[i] = true;
      ++pending;
      whole = whole || t == MessageType::kTfMessage;
    }
    out.topics.push_back(std::move(l));
  }
  if (pending == 0) return out;
  std::vector<bool> done(bag.topics().size(), false);
  std::map<std::size_t, TfTree> trees;  // by topic index, TFMessage topics only
  StaticTransforms statics;             // every .../tf_static transform, for the lidars' mounts
  JointStateMsg js;
  std::vector<PoseMsg> tf;
  try {
    bag.Read(wanted, [&](const BagMessage& m) {
      TopicListing& l = out.topics[m.topic];
      const MessageType mt = MessageTypeFromName(l.topic.type);
      if (done[m.topic] && mt != MessageType::kTfMessage) return;
      auto lag = [&](std::int64_t stamp) {
        if (!l.header_minus_receive_s) l.header_minus_receive_s = static_cast<double>(stamp - m.log_time_ns) * 1e-9;
      };
      try {
        CdrReader r(m.data, m.size);
        if (mt == MessageType::kJointState) {
          DecodeJointState(r, js);
          for (auto n : js.name) l.joints.emplace_back(n);
          lag(js.header.stamp_ns);
        } else if (mt == MessageType::kTfMessage) {
          DecodeTfMessage(r, tf);
          for (const auto& p : tf) {
            trees[m.topic].Add(p, l.static_transforms);
            if (l.static_transforms) statics.Add(p);
          }
          if (!tf.empty() && !l.static_transforms) lag(tf.front().header.stamp_ns);
        } else {
          const Header h = ReadHeader(r);  // LaserScan and every other pose type start with their std_msgs/Header
          l.frame_id = std::string(h.frame_id);
          lag(h.stamp_ns);
          if (mt == MessageType::kOdometry && IsOdometryFrame(l.frame_id)) {
            l.robot_odometry = true;
            l.ground_truth = false;
          }
        }
      } catch (const CdrError& e) {
        if (!done[m.topic])
          warnings.push_back(fmt::format("{}: a message of {} cannot be decoded: {}", *m.file, l.topic.name, e.what()));
      }
      if (!done[m.topic]) {
        done[m.topic] = true;
        if (--pending == 0 && !whole) throw StopReading{};
      }
    });
  } catch (const StopReading&) {
  }
  for (auto& l : out.topics)
    if (l.scan && !l.frame_id.empty()) l.mount = statics.Mount(l.frame_id);
  // Frames of every TFMessage topic; the odometry chain judged over the
  // dynamic and static transforms together.
  TfTree all;
  for (const auto& [i, tree] : trees)
    for (const auto& e : tree.edges()) {
      PoseMsg p;
      p.header.frame_id = e.parent;
      p.child_frame_id = e.child;
      all.Add(p, e.is_static);
    }
  for (const auto& [i, tree] : trees) {
    for (const auto& e : tree.edges()) {
      TopicListing& l = out.topics[i];
      l.frames.push_back(e.child);
      l.tf.push_back({e, all.OdometryFrameAbove(e.child, {}).value_or("")});
    }
    if (tree.dropped_edges() > 0)
      warnings.push_back(fmt::format("{}: topic {} has more than {} distinct transforms; the rest are not listed", path,
                                     out.topics[i].topic.name, TfTree::kMaxEdges));
  }
  return out;
}

}  // namespace umbmark::io::rosbag2
