// Reading calibrate-lidar's recordings (see lidar_drive.hpp).
#include "import/lidar_drive.hpp"

#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "ros2/bag.hpp"
#include "ros2/cdr.hpp"
#include "ros2/messages.hpp"
#include "import/rosbag2_import.hpp"
#include "ros2/scan_messages.hpp"
#include "import/wheel_checks.hpp"

namespace umbmark::io::rosbag2 {

namespace {

std::size_t RequireTyped(const Bag& bag, const std::string& name, const char* flag, const char* type) {
  const auto idx = bag.FindTopic(name);
  if (!idx)
    throw InputError(bag.path(), fmt::format("{} topic {} is not in the recording; its topics are:\n{}", flag, name,
                                             DescribeTopics(bag)));
  const TopicInfo& t = bag.topics()[*idx];
  if (t.type != type) throw InputError(bag.path(), fmt::format("{} topic {} has type {}; it must be {}", flag, name, t.type, type));
  if (t.serialization_format != "cdr")
    throw InputError(bag.path(), fmt::format("topic {} is serialized as '{}', only cdr is supported", name, t.serialization_format));
  return *idx;
}

// A rigid transform in 3-D: unit quaternion (w, x, y, z) and translation.
// (No Eigen here: the readers build without it for the fuzz targets.)
struct Quat {
  double w = 1, x = 0, y = 0, z = 0;
};
struct Vec3 {
  double x = 0, y = 0, z = 0;
};
Quat Multiply(const Quat& a, const Quat& b) {
  return {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
          a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}
Vec3 Rotate(const Quat& q, const Vec3& v) {
  const Quat p = Multiply(Multiply(q, {0, v.x, v.y, v.z}), {q.w, -q.x, -q.y, -q.z});
  return {p.x, p.y, p.z};
}
struct Transform {
  std::string parent;
  Quat q;
  Vec3 t;
};

bool IsBaseFrame(const std::string& f) { return f == "base_link" || f == "base_footprint"; }

// The scan frame's pose in the first base frame above it, composed in 3-D.
std::optional<TfMount> ResolveMount(const std::map<std::string, Transform>& tf, const std::string& scan_frame) {
  if (IsBaseFrame(scan_frame)) return TfMount{{}, false, 0.0, scan_frame + " -> " + scan_frame};
  Quat q;
  Vec3 t;
  std::string cur = scan_frame;
  std::set<std::string> seen;
  while (!IsBaseFrame(cur)) {
    const auto it = tf.find(cur);
    if (it == tf.end() || !seen.insert(cur).second) return std::nullopt;
    const Vec3 moved = Rotate(it->second.q, t);  // parent_T_scan = parent_T_cur * cur_T_scan
    t = {moved.x + it->second.t.x, moved.y + it->second.t.y, moved.z + it->second.t.z};
    q = Multiply(it->second.q, q);
    cur = it->second.parent;
  }
  const double n = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
  if (!(n > 0.0)) return std::nullopt;
  q = {q.w / n, q.x / n, q.y / n, q.z / n};
  const Vec3 x_axis = Rotate(q, {1, 0, 0}), z_axis = Rotate(q, {0, 0, 1});
  TfMount m;
  m.pose = {t.x, t.y, std::atan2(x_axis.y, x_axis.x)};
  m.upside_down = z_axis.z < 0.0;
  m.z_m = t.z;
  m.frames = cur + " -> " + scan_frame;
  return m;
}

// Scans, gyro and the tf-static topic of one recording, appended to `out`.
void ReadSensors(const Bag& bag, const LidarDriveOptions& o, LidarDrive& out, std::map<std::string, Transform>& tf) {
  const std::size_t scan_topic = RequireTyped(bag, o.scan_topic, "--scan", "sensor_msgs/msg/LaserScan");
  std::optional<std::size_t> imu_topic, tf_topic;
  if (!o.imu_topic.empty()) imu_topic = RequireTyped(bag, o.imu_topic, "--imu", "sensor_msgs/msg/Imu");
  if (const auto idx = bag.FindTopic(o.tf_static_topic)) {
    if (bag.topics()[*idx].type != "tf2_msgs/msg/TFMessage")
      throw InputError(bag.path(), fmt::format("--tf-static topic {} has type {}; it must be tf2_msgs/msg/TFMessage",
                                               o.tf_static_topic, bag.topics()[*idx].type));
    tf_topic = idx;
  }
  std::vector<bool> wanted(bag.topics().size(), false);
  wanted[scan_topic] = true;
  if (imu_topic) wanted[*imu_topic] = true;
  if (tf_topic) wanted[*tf_topic] = true;
  std::vector<PoseMsg> transforms;
  std::size_t scans = 0, imus = 0;
  scan::LaserScan s;
  std::string_view frame;
  bag.Read(wanted, [&](const BagMessage& m) {
    const TopicInfo& topic = bag.topics()[m.topic];
    try {
      CdrReader r(m.data, m.size);
      if (m.topic == scan_topic) {
        ++scans;
        DecodeLaserScan(r, s, frame);
        if (out.scan_frame.empty()) out.scan_frame = std::string(frame);
        if (!out.scans.empty() && s.t_ns <= out.scans.back().t_ns)
          throw InputError(*m.file, fmt::format("topic {}, message {}: header stamp {} s does not increase (previous {} s)",
                                                topic.name, scans, StampText(s.t_ns), StampText(out.scans.back().t_ns)));
        if (!(std::isfinite(s.angle_min) && std::isfinite(s.angle_increment) && s.angle_increment != 0.0))
          throw InputError(*m.file, fmt::format("topic {}, message {}: angle_min {} / angle_increment {} make no beams",
                                                topic.name, scans, s.angle_min, s.angle_increment));
        out.scans.push_back(s);
      } else if (imu_topic && m.topic == *imu_topic) {
        ++imus;
        const ImuRate g = DecodeImuRate(r);
        if (!g.has_rate)
          throw InputError(*m.file, fmt::format("topic {}, message {}: the IMU has no angular velocity "
                                                "(angular_velocity_covariance[0] is -1)",
                                                topic.name, imus));
        if (!std::isfinite(g.rate_z))
          throw InputError(*m.file, fmt::format("topic {}, message {}: angular_velocity.z is not finite", topic.name, imus));
        if (!out.gyro.empty() && g.header.stamp_ns <= out.gyro.back().t_ns)
          throw InputError(*m.file, fmt::format("topic {}, message {}: header stamp {} s does not increase", topic.name, imus,
                                                StampText(g.header.stamp_ns)));
        out.gyro.push_back({g.header.stamp_ns, g.rate_z});
      } else {
        DecodeTfMessage(r, transforms);
        for (const PoseMsg& p : transforms)
          tf[std::string(p.child_frame_id)] = {std::string(p.header.frame_id), Quat{p.qw, p.qx, p.qy, p.qz}, Vec3{p.x, p.y, p.z}};
      }
    } catch (const CdrError& e) {
      throw InputError(*m.file, fmt::format("topic {}: cannot decode: {}", topic.name, e.what()));
    }
  });
  if (scans == 0) throw InputError(bag.path(), fmt::format("--scan topic {} has no messages", o.scan_topic));
  if (imu_topic && imus == 0) throw InputError(bag.path(), fmt::format("--imu topic {} has no messages", o.imu_topic));
}

}  // namespace

std::string LidarDriveOptions::Validate() const {
  if (scan_topic.empty()) return "scan_topic: --scan TOPIC is required";
  if (wheels_topic.empty() == odometry_topic.empty()) return "exactly one wheel source is needed: --wheels TOPIC or --odometry TOPIC";
  if (tf_static_topic.empty()) return "tf_static_topic: --tf-static needs a topic name";
  return {};
}

LidarDrive ReadLidarDrive(const std::vector<std::string>& bags, const RobotParams& robot, const LidarDriveOptions& o) {
  if (const std::string err = o.Validate(); !err.empty()) throw InvalidOptions(err);
  LidarDrive out;
  std::map<std::string, Transform> tf;
  for (const std::string& path : bags) {
    // Wheels: the import's reading, one run per recording (no pause split).
    Rosbag2ImportOptions io;
    io.kind = ExperimentKind::kFree;
    io.wheels_topic = o.wheels_topic;
    io.odometry_topic = o.odometry_topic;
    io.pause_s = 0.0;
    Rosbag2Import wheels = ImportRosbag2({path}, robot, io);
    for (auto& w : wheels.warnings) out.warnings.push_back(std::move(w));
    const std::int64_t t0 = wheels.recordings.front().first_stamp_ns;
    if (!out.wheels.empty() && t0 <= out.wheels.back().t_ns)
      throw InputError(path, fmt::format("its wheel data start at {} s, before the previous recording's end ({} s): give the "
                                         "BAGs in time order, one drive after another",
                                         StampText(t0), StampText(out.wheels.back().t_ns)));
    for (const TrajectoryRun& run : wheels.runs.runs)
      for (std::size_t i = 0; i < run.size(); ++i)
        out.wheels.push_back({t0 + static_cast<std::int64_t>(std::llround(run.t_s[i] * 1e9)), run.dist_left_m[i], run.dist_right_m[i]});
    std::vector<std::string> notes;
    const Bag bag = Bag::Open(path, notes);
    const std::size_t before = out.scans.size();
    if (before > 0) {
      // Stamps must go on increasing across recordings too.
      LidarDrive part;
      part.scan_frame = out.scan_frame;
      ReadSensors(bag, o, part, tf);
      if (part.scans.front().t_ns <= out.scans.back().t_ns)
        throw InputError(path, "its scans start before the previous recording's end: give the BAGs in time order");
      for (auto& s : part.scans) out.scans.push_back(std::move(s));
      for (auto& g : part.gyro) out.gyro.push_back(g);
    } else {
      ReadSensors(bag, o, out, tf);
    }
  }
  out.mount = ResolveMount(tf, out.scan_frame);
  if (!out.mount && !tf.empty())
    out.warnings.push_back(fmt::format("{} reaches no base_link or base_footprint from the scan's frame '{}': the fitted "
                                       "mount is not compared with it",
                                       o.tf_static_topic, out.scan_frame));
  return out;
}

}  // namespace umbmark::io::rosbag2
