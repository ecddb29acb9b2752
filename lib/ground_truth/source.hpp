// Where the ground truth of an imported recording comes from: one interface,
// one file per source, so that another source touches this folder only and
// the importer (import/rosbag2_import.cpp) never asks which one it has:
//   pose_topic.hpp    a motion-capture pose topic (PoseStamped,
//                     PoseWithCovarianceStamped, Odometry): --ground-truth
//   tf_frame.hpp      one frame of a tf2_msgs/TFMessage topic:
//                     --ground-truth TOPIC --ground-truth-frame FRAME
//   scan_source.hpp   the robot's own 2-D lidar with an optional gyro:
//                     --scan [--imu] (registration in scan_ground_truth.hpp)
//   make_source.cpp   the registry: the built-in sources by name ("scan",
//                     "topic"), RegisterGroundTruthSource for more, and the
//                     one place that picks a source from the options.
// Another source is a class in a file of its own and one registration: in
// make_source.cpp for a built-in one, or RegisterGroundTruthSource from any
// program (tests/test_ground_truth_source.cpp registers one that lives in
// the test alone); an import names it with Rosbag2ImportOptions::
// ground_truth_source.
//
// The importer drives a source through each recording in this order:
//   Open       which topics to decode in the importer's pass with the wheels
//   OnMessage  each of their messages, in recording order
//   EndOfPass  what needs the whole pass (a /tf frame's static anchor),
//              duplicates as warnings; StampLag for the clock check
//   ReadRuns   with the runs the importer cut from the wheels (the lidar
//              registers its scans per run here)
//   Run(k)     run k's ground truth, interpolated at the wheel samples
//   EndRecording
// and after the last recording Finish (what the manifest and the result
// carry besides the runs' poses).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/pose2.hpp"
#include "core/runs.hpp"
#include "formats/campaign_writer.hpp"
#include "ground_truth/scan_ground_truth.hpp"
#include "ros2/bag.hpp"
#include "ros2/cdr.hpp"

namespace umbmark::io::rosbag2 {

/// A ground-truth pose at a time; yaw unwrapped along the recording.
struct GroundTruthSample {
  std::int64_t t_ns = 0;
  double x = 0.0, y = 0.0, yaw = 0.0;
};

/// What selects and configures the source (the import's options).
struct GroundTruthOptions {
  /// A registered source by name (RegisterGroundTruthSource; the built-in
  /// "scan" and "topic" too); empty: "scan" with scan_topic, "topic" with
  /// topic, else no ground truth.
  std::string source;
  std::string topic;                ///< --ground-truth: a pose or TFMessage topic
  std::string frame;                ///< --ground-truth-frame: the TFMessage child frame to follow
  std::string scan_topic;           ///< --scan: sensor_msgs/msg/LaserScan
  std::string imu_topic;            ///< --imu: sensor_msgs/msg/Imu (with --scan)
  std::optional<Pose2> scan_pose;   ///< --scan-pose: the lidar in the robot frame
  /// --tf-static: the lidar's static transform topic; empty = /tf_static,
  /// else the only topic named .../tf_static (a namespaced robot).
  std::string tf_static_topic;
  bool scan_upside_down = false;    ///< --scan-upside-down: the lidar is mounted upside down (beams mirrored)
  bool log_time = false;            ///< ground-truth stamps: receive time instead of header.stamp
  double max_gap_s = 0.1;           ///< interpolate only between ground truth this close [s]
};

/// A recording's runs as the importer cut them from the wheels.
struct RecordingRuns {
  std::vector<WheelTravel> wheels;  ///< every wheel sample (travel in metres), time order
  /// Each run's first and last index into `wheels` (runs dropped later for
  /// a gap in the wheel topic included).
  std::vector<std::pair<std::size_t, std::size_t>> spans;
  std::size_t first_run = 0;  ///< runs of earlier recordings (these are numbered first_run + 1, ...)
  double wheelbase_m = 0.0;   ///< the robot file's, for the odometry's predictions
  std::string left_joint, right_joint;  ///< the wheel joints used (JointState), for messages
};

/// One run's ground truth: samples in time order and the largest gap
/// between two of them that may be interpolated across.
struct RunGroundTruth {
  const std::vector<GroundTruthSample>* samples = nullptr;
  std::int64_t max_gap_ns = 0;
};

/// The median header stamp minus receive time of a source's messages, for
/// the importer's check that the wheels' and the ground truth's clocks agree.
struct StampLag {
  double median_s = 0.0;
  std::string topic;
};

/// What a source adds to an import besides the runs' poses. Each source
/// that has a report of its own adds a member here.
struct GroundTruthExtras {
  std::optional<GroundTruthNoise> noise;   ///< the manifest's [ground_truth] sigmas, when the source measures them
  std::vector<ManifestKey> manifest_keys;  ///< further [ground_truth] keys (source = "scan", ...)
  std::vector<ScanGroundTruth> scan;       ///< the lidar: per recording, what the scans and the gyro gave
};

class GroundTruthSource {
 public:
  virtual ~GroundTruthSource() = default;

  /// The ground truth as the user named it ("--ground-truth /mocap"), for messages.
  virtual std::string Name() const = 0;
  /// True when the ground truth is a pose the recording carries as it is,
  /// which may be the robot's own odometry: the importer then checks it
  /// against the wheels (swapped joints; ground truth that follows the
  /// wheel odometry is refused). False for a source computed from other
  /// sensors (the lidar registration uses the wheels as its prior).
  virtual bool CheckAgainstOdometry() const = 0;

  /// Topics to decode in the importer's pass over `bag` with the wheel
  /// topic (checked: InputError naming the file and the flag).
  virtual std::vector<std::size_t> Open(const Bag& bag, std::size_t wheel_topic) = 0;
  /// One message of those topics, in recording order; `index` numbers them
  /// (for messages). May throw CdrError (the importer names the message).
  virtual void OnMessage(CdrReader& r, const BagMessage& m, const TopicInfo& topic, std::size_t index) = 0;
  /// After the pass. `odometry_frame`: the --odometry topic's frame_id
  /// ("" for JointState). Throws InputError; warnings are appended.
  virtual void EndOfPass(const Bag& bag, const std::string& odometry_frame, std::vector<std::string>& warnings) = 0;
  /// The messages' clock against the receive times; nullopt when the
  /// source has no such messages (the lidar: its clock is its own check).
  virtual std::optional<StampLag> Lag() const { return std::nullopt; }
  /// With the runs: whatever needs them (the lidar's registration).
  virtual void ReadRuns(const Bag& bag, const RecordingRuns& runs, std::vector<std::string>& warnings) = 0;
  /// Run k of the recording (k indexes RecordingRuns::spans).
  virtual RunGroundTruth Run(std::size_t k) const = 0;
  /// Messages that gave the recording's ground truth (the summary's count).
  virtual std::size_t Messages() const = 0;
  /// The recording's runs are built; its per-run data may go.
  virtual void EndRecording() = 0;
  /// After every recording.
  virtual GroundTruthExtras Finish() = 0;
};

/// Builds a source for one import from its options.
using GroundTruthSourceFactory = std::function<std::unique_ptr<GroundTruthSource>(const GroundTruthOptions&)>;

/// Adds `make` under `name` (replacing a source of that name, a built-in
/// one too); thread-safe. An import picks it with GroundTruthOptions::source.
void RegisterGroundTruthSource(const std::string& name, GroundTruthSourceFactory make);
/// Removes a registered source; false when there was none of that name.
bool UnregisterGroundTruthSource(const std::string& name);
/// The registered names, sorted ("scan", "topic", and any added).
std::vector<std::string> GroundTruthSourceNames();

/// The source `options` name: options.source when given (InvalidOptions
/// naming it and the registered ones when it is not registered), else
/// "scan" with scan_topic, "topic" with topic, else nullptr for an import
/// without ground truth.
std::unique_ptr<GroundTruthSource> MakeGroundTruthSource(const GroundTruthOptions& options);

}  // namespace umbmark::io::rosbag2
