// rosbag2 import (see rosbag2_import.hpp and the contract's "ROS 2 recordings").
#include "io/rosbag2/rosbag2_import.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>

#include <fmt/format.h>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "io/rosbag2/messages.hpp"

namespace umbmark::io::rosbag2 {

namespace {

constexpr double kStillM = 1e-6;  // a wheel is still when its travel changes less than this

struct WheelSample {
  std::int64_t t_ns;
  double left, right;  // cumulative travel [m] (JointState) or pose x, y, yaw (Odometry, converted later)
  double yaw = 0.0;
};
struct GtSample {
  std::int64_t t_ns;
  double x, y, yaw;  // yaw unwrapped after reading
};

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
    const std::string names = fmt::format("{}", fmt::join(m.name, ", "));
    auto find = [&](const std::string& wanted, const char* side, std::size_t& idx, std::string& resolved) {
      if (!wanted.empty()) {
        for (std::size_t i = 0; i < m.name.size(); ++i)
          if (m.name[i] == wanted) {
            idx = i;
            resolved = wanted;
            return true;
          }
        why = fmt::format("joint '{}' is not in the message; its joints are: {}", wanted, names);
        return false;
      }
      std::vector<std::size_t> hits;
      for (std::size_t i = 0; i < m.name.size(); ++i)
        if (Lower(m.name[i]).find(side) != std::string::npos) hits.push_back(i);
      if (hits.size() != 1) {
        why = fmt::format("{} joint names contain '{}' (joints: {}); name the wheel with --{}-joint", hits.size(), side,
                          names.empty() ? "none" : names, side);
        return false;
      }
      idx = hits[0];
      resolved = std::string(m.name[idx]);
      return true;
    };
    if (!find(left_, "left", li_, resolved_left_) || !find(right_, "right", ri_, resolved_right_)) return false;
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

std::string Where(const BagMessage& m, const TopicInfo& t, std::size_t index) {
  return m.offset > 0 ? fmt::format("topic {} ({}), message {} (record at byte {})", t.name, t.type, index, m.offset)
                      : fmt::format("topic {} ({}), message {}", t.name, t.type, index);
}

// Checks that a stream's stamps increase; `what` names it for the message.
void CheckIncreasing(std::int64_t prev, std::int64_t t, std::size_t count, const BagMessage& m, const TopicInfo& topic,
                     std::size_t index, StampSource time) {
  if (count > 0 && t <= prev) {
    auto sec = [](std::int64_t ns) { return fmt::format("{}.{:09d}", ns / 1000000000, std::abs(ns % 1000000000)); };
    throw InputError(*m.file, fmt::format("{}: {} stamp {} s does not increase (previous {} s){}", Where(m, topic, index),
                                          time == StampSource::kHeader ? "header" : "receive", sec(t), sec(prev),
                                          time == StampSource::kHeader ? "; try --time log" : ""));
  }
}

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
// NaN when no sample lies within max_gap on both sides.
struct GtInterpolator {
  const std::vector<GtSample>& gt;
  std::int64_t max_gap_ns;
  std::size_t j = 0;
  Pose2 At(std::int64_t t) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    if (gt.empty() || t < gt.front().t_ns || t > gt.back().t_ns) return {nan, nan, nan};
    while (j + 1 < gt.size() && gt[j + 1].t_ns <= t) ++j;
    while (j > 0 && gt[j].t_ns > t) --j;
    const GtSample& a = gt[j];
    if (a.t_ns == t) return {a.x, a.y, a.yaw};
    const GtSample& b = gt[j + 1];
    if (t - a.t_ns > max_gap_ns || b.t_ns - t > max_gap_ns) return {nan, nan, nan};
    const double u = static_cast<double>(t - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns);
    return {a.x + u * (b.x - a.x), a.y + u * (b.y - a.y), a.yaw + u * (b.yaw - a.yaw)};
  }
};

struct TopicChoice {
  std::size_t wheels = 0;
  std::optional<std::size_t> gt;
  MessageType gt_type = MessageType::kOther;
};

std::size_t RequireTopic(const Bag& bag, const std::string& name, const char* flag) {
  const auto idx = bag.FindTopic(name);
  if (!idx)
    throw InputError(bag.path(), fmt::format("{} topic {} is not in the recording; its topics are:\n{}", flag, name,
                                             DescribeTopics(bag)));
  const TopicInfo& t = bag.topics()[*idx];
  if (t.serialization_format != "cdr")
    throw InputError(bag.path(), fmt::format("topic {} is serialized as '{}', only cdr is supported", name,
                                             t.serialization_format));
  return *idx;
}

TopicChoice ChooseTopics(const Bag& bag, const Rosbag2ImportOptions& o) {
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
  if (!o.ground_truth_topic.empty()) {
    c.gt = RequireTopic(bag, o.ground_truth_topic, "--ground-truth");
    const TopicInfo& g = bag.topics()[*c.gt];
    c.gt_type = MessageTypeFromName(g.type);
    if (!IsPoseType(c.gt_type))
      throw InputError(bag.path(), fmt::format("--ground-truth topic {} has type {}, which holds no pose; ground truth must be "
                                               "geometry_msgs/msg/PoseStamped, geometry_msgs/msg/PoseWithCovarianceStamped, "
                                               "nav_msgs/msg/Odometry or tf2_msgs/msg/TFMessage", g.name, g.type));
    if (*c.gt == c.wheels) throw InputError(bag.path(), fmt::format("topic {} is both the wheel source and the ground truth", g.name));
  }
  return c;
}

void CheckFinite(const PoseMsg& p, const BagMessage& m, const TopicInfo& t, std::size_t index) {
  for (double v : {p.x, p.y, p.qx, p.qy, p.qz, p.qw})
    if (!std::isfinite(v)) throw InputError(*m.file, fmt::format("{}: pose is not finite (NaN or infinite)", Where(m, t, index)));
  if (p.qx * p.qx + p.qy * p.qy + p.qz * p.qz + p.qw * p.qw < 1e-12)
    throw InputError(*m.file, fmt::format("{}: orientation quaternion is zero", Where(m, t, index)));
}

struct RecordingData {
  std::vector<WheelSample> wheels;
  std::vector<GtSample> gt;
  std::string left_joint, right_joint;
};

// One streaming pass over the recording: decodes the wheel and ground-truth
// topics into time-stamped samples (the only per-message state kept). One
// callback handles every message type so the bag is read once.
RecordingData ReadRecording(const Bag& bag, const TopicChoice& c, const RobotParams& robot,
                            const Rosbag2ImportOptions& o) {
  RecordingData d;
  std::vector<bool> wanted(bag.topics().size(), false);
  wanted[c.wheels] = true;
  if (c.gt) wanted[*c.gt] = true;
  const TopicInfo& wt = bag.topics()[c.wheels];
  const bool joints = !o.wheels_topic.empty();
  JointPicker picker(o.left_joint, o.right_joint);
  JointStateMsg js;
  std::vector<PoseMsg> tf;
  std::set<std::string> frames_seen;
  std::size_t wheel_index = 0, gt_index = 0, tf_matches = 0;
  const double rl = 0.5 * robot.wheel_diameter_left_m, rr = 0.5 * robot.wheel_diameter_right_m;
  bag.Read(wanted, [&](const BagMessage& m) {
    const TopicInfo& topic = bag.topics()[m.topic];
    const bool is_wheels = m.topic == c.wheels;
    const std::size_t index = is_wheels ? ++wheel_index : ++gt_index;
    try {
      CdrReader r(m.data, m.size);
      if (is_wheels) {
        WheelSample s{};
        std::int64_t stamp;
        if (joints) {
          DecodeJointState(r, js);
          std::size_t li = 0, ri = 0;
          std::string why;
          if (!picker.Pick(js, li, ri, why)) throw InputError(*m.file, fmt::format("{}: {}", Where(m, topic, index), why));
          if (js.position.size() != js.name.size())
            throw InputError(*m.file, fmt::format("{}: {} joint names but {} positions", Where(m, topic, index),
                                                  js.name.size(), js.position.size()));
          s.left = js.position[li] * rl;
          s.right = js.position[ri] * rr;
          if (!std::isfinite(s.left) || !std::isfinite(s.right))
            throw InputError(*m.file, fmt::format("{}: wheel position is not finite", Where(m, topic, index)));
          stamp = js.header.stamp_ns;
        } else {
          const PoseMsg p = DecodeOdometry(r);
          CheckFinite(p, m, topic, index);
          s.left = p.x;
          s.right = p.y;
          s.yaw = p.Yaw();
          stamp = p.header.stamp_ns;
        }
        s.t_ns = o.time == StampSource::kHeader ? stamp : m.log_time_ns;
        CheckIncreasing(d.wheels.empty() ? 0 : d.wheels.back().t_ns, s.t_ns, d.wheels.size(), m, topic, index, o.time);
        d.wheels.push_back(s);
        return;
      }
      auto add_gt = [&](const PoseMsg& p) {
        CheckFinite(p, m, topic, index);
        const std::int64_t t = o.time == StampSource::kHeader ? p.header.stamp_ns : m.log_time_ns;
        CheckIncreasing(d.gt.empty() ? 0 : d.gt.back().t_ns, t, d.gt.size(), m, topic, index, o.time);
        d.gt.push_back({t, p.x, p.y, p.Yaw()});
      };
      switch (c.gt_type) {
        case MessageType::kPoseStamped: add_gt(DecodePoseStamped(r)); break;
        case MessageType::kPoseWithCovarianceStamped: add_gt(DecodePoseWithCovarianceStamped(r)); break;
        case MessageType::kOdometry: add_gt(DecodeOdometry(r)); break;
        case MessageType::kTfMessage:
          DecodeTfMessage(r, tf);
          for (const auto& p : tf) {
            if (frames_seen.size() < 64) frames_seen.insert(std::string(p.child_frame_id));
            if (p.child_frame_id == o.ground_truth_frame) {
              ++tf_matches;
              add_gt(p);
            }
          }
          break;
        default: break;
      }
    } catch (const CdrError& e) {
      throw InputError(*m.file, fmt::format("{}: cannot decode: {}", Where(m, topic, index), e.what()));
    }
  });
  if (c.gt && c.gt_type == MessageType::kTfMessage && tf_matches == 0) {
    throw InputError(bag.path(), fmt::format("--ground-truth {}: no transform with child_frame_id '{}'{}; child frames seen: {}",
                                             o.ground_truth_topic, o.ground_truth_frame,
                                             o.ground_truth_frame.empty() ? " (set --ground-truth-frame)" : "",
                                             frames_seen.empty() ? std::string("none") : fmt::format("{}", fmt::join(frames_seen, ", "))));
  }
  if (d.wheels.size() < 2)
    throw InputError(bag.path(), fmt::format("wheel topic {} has {} message(s); at least two are needed", wt.name, d.wheels.size()));
  if (c.gt && d.gt.empty())
    throw InputError(bag.path(), fmt::format("--ground-truth topic {} has no messages", o.ground_truth_topic));
  // Unwrap the ground-truth heading so that interpolation and total rotation are continuous.
  for (std::size_t i = 1; i < d.gt.size(); ++i) d.gt[i].yaw = d.gt[i - 1].yaw + WrapAngle(d.gt[i].yaw - d.gt[i - 1].yaw);
  if (!joints) OdometryToWheels(d.wheels, robot.wheelbase_m, o.integrator);
  d.left_joint = picker.left();
  d.right_joint = picker.right();
  return d;
}

}  // namespace

std::string Rosbag2ImportOptions::Validate() const {
  if (wheels_topic.empty() == odometry_topic.empty()) return "exactly one wheel source is needed: --wheels TOPIC or --odometry TOPIC";
  if (!odometry_topic.empty() && (!left_joint.empty() || !right_joint.empty()))
    return "--left-joint/--right-joint apply to --wheels (JointState), not to --odometry";
  if (kind == ExperimentKind::kSquare && !(side_m > 0.0 && std::isfinite(side_m)))
    return fmt::format("side_m = {}: a square experiment needs --side > 0", side_m);
  if (kind == ExperimentKind::kBackAndForth && !(distance_m > 0.0 && std::isfinite(distance_m)))
    return fmt::format("distance_m = {}: a back_and_forth experiment needs --distance > 0", distance_m);
  if (!(pause_s >= 0.0) || !std::isfinite(pause_s)) return fmt::format("pause_s = {}: must be >= 0", pause_s);
  if (!(max_gt_gap_s > 0.0) || !std::isfinite(max_gt_gap_s)) return fmt::format("max_gt_gap_s = {}: must be > 0", max_gt_gap_s);
  if (!ground_truth_frame.empty() && ground_truth_topic.empty()) return "--ground-truth-frame needs --ground-truth";
  return {};
}

std::string DescribeTopics(const Bag& bag) {
  std::string out;
  for (const auto& t : bag.topics()) out += fmt::format("  {}  {}  ({} messages)\n", t.name, t.type, t.count);
  if (bag.topics().empty()) out = "  (none)\n";
  out.pop_back();
  return out;
}

// Per recording: read, split, then build each run (relative travel, ground
// truth re-expressed, direction); kept in one function so the contract's
// run rules read in one place.
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
  for (const auto& path : bags) {
    const Bag bag = Bag::Open(path, out.warnings);
    const TopicChoice choice = ChooseTopics(bag, o);
    const RecordingData d = ReadRecording(bag, choice, robot, o);
    RecordingSummary rs{path, d.wheels.size(), d.gt.size(), 0, d.left_joint, d.right_joint,
                        static_cast<double>(d.wheels.back().t_ns - d.wheels.front().t_ns) * 1e-9};
    const auto spans = SplitRuns(d.wheels, o.pause_s);
    if (spans.empty())
      throw InputError(path, fmt::format("the wheels never move on {} ({} samples): no run to import",
                                         bag.topics()[choice.wheels].name, d.wheels.size()));
    GtInterpolator interp{d.gt, static_cast<std::int64_t>(std::llround(o.max_gt_gap_s * 1e9))};
    const std::int64_t t0 = d.wheels.front().t_ns;
    for (const auto& [a, b] : spans) {
      TrajectoryRun run;
      run.run = std::to_string(out.runs.runs.size() + 1);
      std::optional<Pose2> origin;
      double gt_first_yaw = 0.0, gt_last_yaw = 0.0;
      for (std::size_t i = a; i <= b; ++i) {
        const WheelSample& s = d.wheels[i];
        run.t_s.push_back(static_cast<double>(s.t_ns - t0) * 1e-9);
        run.dist_left_m.push_back(s.left - d.wheels[a].left);
        run.dist_right_m.push_back(s.right - d.wheels[a].right);
        Pose2 g = choice.gt ? interp.At(s.t_ns) : Pose2{NAN, NAN, NAN};
        if (!std::isnan(g.x)) {
          // Ground truth re-expressed in the frame of the run's first ground-truth sample.
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
      if (choice.gt && !run.HasGroundTruth(0))
        out.warnings.push_back(fmt::format("{}: run {} has no ground truth within {} s of its first sample; its ground truth "
                                           "is relative to its first measured pose", path, run.run, o.max_gt_gap_s));
      if (o.kind == ExperimentKind::kSquare) {
        // Direction from the total rotation: ground truth, or odometry without it.
        const bool from_gt = origin.has_value();
        const double total = from_gt ? gt_last_yaw - gt_first_yaw
                                     : ((run.dist_right_m.back() - run.dist_left_m.back()) / robot.wheelbase_m);
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
      out.runs.runs.push_back(std::move(run));
      ++rs.runs;
    }
    out.recordings.push_back(rs);
  }
  return out;
}

BagListing ListRosbag2(const std::string& path, std::vector<std::string>& warnings) {
  const Bag bag = Bag::Open(path, warnings);
  BagListing out{path, bag.files(), {}};
  std::vector<bool> wanted(bag.topics().size(), false);
  std::size_t pending = 0;
  for (std::size_t i = 0; i < bag.topics().size(); ++i) {
    TopicListing l;
    l.topic = bag.topics()[i];
    const MessageType t = MessageTypeFromName(l.topic.type);
    l.wheels = t == MessageType::kJointState || t == MessageType::kOdometry;
    l.ground_truth = IsPoseType(t);
    if ((t == MessageType::kJointState || t == MessageType::kTfMessage) && l.topic.count > 0) {
      wanted[i] = true;
      ++pending;
    }
    out.topics.push_back(std::move(l));
  }
  if (pending == 0) return out;
  // Joint names and child frames from the first message of each such topic.
  std::vector<bool> done(bag.topics().size(), false);
  JointStateMsg js;
  std::vector<PoseMsg> tf;
  try {
    bag.Read(wanted, [&](const BagMessage& m) {
      if (done[m.topic]) return;
      done[m.topic] = true;
      TopicListing& l = out.topics[m.topic];
      try {
        CdrReader r(m.data, m.size);
        if (MessageTypeFromName(l.topic.type) == MessageType::kJointState) {
          DecodeJointState(r, js);
          for (auto n : js.name) l.joints.emplace_back(n);
        } else {
          DecodeTfMessage(r, tf);
          for (const auto& p : tf) l.frames.emplace_back(p.child_frame_id);
        }
      } catch (const CdrError& e) {
        warnings.push_back(fmt::format("{}: first message of {} cannot be decoded: {}", *m.file, l.topic.name, e.what()));
      }
      if (--pending == 0) throw StopReading{};
    });
  } catch (const StopReading&) {
  }
  return out;
}

}  // namespace umbmark::io::rosbag2
