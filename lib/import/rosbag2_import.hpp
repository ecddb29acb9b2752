// `import rosbag2`: turns ROS 2 recordings into the contract's campaign
// (robot + one experiment + trajectory runs with cumulative wheel travel and
// ground truth), as fixed by the contract's section "ROS 2 recordings":
// wheel travel from JointState positions times the wheel radius, or from an
// Odometry topic inverted with the wheelbase; ground truth from one source
// (ground_truth/source.hpp: a pose topic, a /tf frame, the lidar)
// interpolated at the wheel samples; runs split at pauses; each run
// re-expressed relative to its first sample.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/pose2.hpp"
#include "core/robot.hpp"
#include "core/runs.hpp"
#include "formats/campaign_writer.hpp"
#include "ground_truth/scan_ground_truth.hpp"
#include "ros2/bag.hpp"
#include "ros2/bag_text.hpp"
#include "ros2/tf_tree.hpp"
#include "kinematics/diff_drive.hpp"

namespace umbmark::io::rosbag2 {

enum class StampSource { kHeader, kLog };

struct Rosbag2ImportOptions {
  ExperimentKind kind = ExperimentKind::kSquare;
  double side_m = 0.0;      ///< square: side length (required)
  double distance_m = 0.0;  ///< back_and_forth: leg length (required)
  /// Wheel source, exactly one: a JointState topic (with its two joints;
  /// empty = the only joint whose name contains "left" resp. "right") or an
  /// Odometry topic.
  std::string wheels_topic, left_joint, right_joint;
  std::string odometry_topic;
  /// Integrator the robot's odometry used (for --odometry).
  Integrator integrator = Integrator::kArc;
  /// Optional ground truth; for a TFMessage topic the child frame to follow.
  std::string ground_truth_topic, ground_truth_frame;
  /// Time of the wheel messages, and of the ground truth (unset: the same).
  /// Or ground truth from the robot's lidar (scan_ground_truth.hpp): a
  /// LaserScan topic, the lidar's pose when /tf_static lacks it, and an
  /// optional gyro (Imu topic).
  std::string scan_topic, imu_topic;
  std::optional<Pose2> scan_pose;
  bool scan_upside_down = false;  ///< --scan-upside-down: the lidar is mounted upside down (beams mirrored)
  std::string tf_static_topic;  ///< --tf-static (scan_ground_truth.hpp); empty: /tf_static or the only .../tf_static
  /// A ground-truth source by its registered name (ground_truth/source.hpp:
  /// RegisterGroundTruthSource); empty (the default): the one the topics
  /// above name ("scan" with scan_topic, "topic" with ground_truth_topic).
  std::string ground_truth_source;
  StampSource time = StampSource::kHeader;
  std::optional<StampSource> ground_truth_time;
  StampSource GroundTruthTime() const { return ground_truth_time.value_or(time); }
  double pause_s = 2.0;       ///< split at standstills this long; 0 = one run per recording
  double max_gt_gap_s = 0.1;  ///< interpolate only between ground truth this close
  /// Empty when valid, else a message naming the bad field.
  std::string Validate() const;
};

/// What was read from one recording.
struct RecordingSummary {
  std::string path;
  std::size_t wheel_messages = 0, ground_truth_messages = 0;
  std::size_t runs = 0;
  std::size_t runs_dropped = 0;  ///< runs with a gap in the wheel topic (see warnings)
  std::string left_joint, right_joint;  ///< the joints used (JointState)
  double duration_s = 0.0;
  std::int64_t first_stamp_ns = 0;  ///< the first wheel sample's stamp (the runs' t_s count from it)
};

struct Rosbag2Import {
  Experiment experiment;  ///< kind, side/distance, file = "runs.csv"
  TrajectoryData runs;    ///< dist_left_m/dist_right_m, ground truth relative to each run's start
  std::vector<RecordingSummary> recordings;
  /// With --scan: per recording what the lidar and gyro gave (the runs'
  /// poses moved into `runs`), and the registration's noise for the manifest.
  std::vector<ScanGroundTruth> scan;
  std::optional<GroundTruthNoise> ground_truth;
  /// The manifest's further [ground_truth] keys from the source (the lidar's
  /// source = "scan", its pose and gyro; none for a pose topic).
  std::vector<ManifestKey> ground_truth_keys;
  std::vector<std::string> warnings;
};

/// Reads the recordings in order (runs numbered 1..N across them). `robot`
/// is what the odometry used (wheel radii for JointState, wheelbase for
/// Odometry and the direction from odometry). Throws InvalidOptions for bad
/// options, InputError naming the file (and topic, message or byte offset)
/// for anything wrong with the data.
Rosbag2Import ImportRosbag2(const std::vector<std::string>& bags, const RobotParams& robot,
                            const Rosbag2ImportOptions& options);

/// One topic of `--list`, with what it can serve as.
struct TopicListing {
  TopicInfo topic;
  bool wheels = false;        ///< JointState or Odometry
  bool ground_truth = false;  ///< a pose type (an Odometry in an odometry frame is not: robot_odometry)
  bool robot_odometry = false;  ///< Odometry whose header.frame_id is an odometry frame (odom): the robot's own
  bool scan = false;          ///< LaserScan: --scan
  bool imu = false;           ///< Imu: --imu
  bool static_transforms = false;  ///< a .../tf_static topic (latched: its rate means nothing)
  std::string frame_id;       ///< header.frame_id of the first message (LaserScan, Odometry)
  std::optional<LidarMount> mount;  ///< LaserScan: its frame's mount from the static transforms
  std::vector<std::string> joints;  ///< JointState: joint names of its first message
  std::vector<std::string> frames;  ///< TFMessage: every child frame of the topic
  /// Header stamp minus receive time of the topic's first message [s]: a
  /// clock that is off (a motion-capture PC 37 s ahead, simulation time)
  /// shows here, for choosing --time.
  std::optional<double> header_minus_receive_s;
  /// TFMessage: every transform (parent -> child, rate) of the topic, with
  /// the odometry frame its chain runs through ("" when none: a candidate
  /// for --ground-truth-frame).
  struct Frame {
    TfEdge edge;
    std::string through_odometry;
  };
  std::vector<Frame> tf;
};
struct BagListing {
  std::string path;
  std::vector<std::string> files;
  std::vector<TopicListing> topics;
};
BagListing ListRosbag2(const std::string& bag, std::vector<std::string>& warnings);

}  // namespace umbmark::io::rosbag2
