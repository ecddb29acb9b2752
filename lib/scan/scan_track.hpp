// The lidar as ground truth for one run: the robot's pose at every scan,
// relative to where it stood before the run, found by scan registration.
//
//   still before        moving (chained through keyframes)        still after
//   |||||||||||  t_start  . . . . . . . . . . . . . . . .  t_end  |||||||||||
//   averaged per beam -> the reference        averaged per beam, registered
//   (its pose is the run's start)             against the reference -> the end
//
// The start and end poses (what the return error is made of) come from every
// still scan before and after the run, averaged beam by beam, so their noise
// is the single scan's over sqrt(scans). The scans in between are chained:
// each is registered against the current keyframe (the reference first) from
// the wheel odometry's prediction, and becomes the next keyframe when it has
// moved too far from it or overlaps too little. The end is registered against
// the reference directly when it overlaps it (a square returns to its start),
// else against the last keyframe. Every registration's information matrix is
// checked: a scene that leaves a direction undetermined is refused.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/pose2.hpp"
#include "scan/laser_scan.hpp"
#include "scan/scan_matcher.hpp"

namespace umbmark::scan {

struct StampedPose {
  std::int64_t t_ns = 0;
  Pose2 pose;
};

/// The time span of one run: its first and last wheel sample (the robot
/// still at both), and the still stretches around it (from the pause's first
/// sample before, to the pause's last sample after; equal to t_start / t_end
/// when there is no pause).
struct RunWindow {
  std::int64_t still_from_ns = 0, t_start_ns = 0, t_end_ns = 0, still_to_ns = 0;
};

/// The scans of one run, each list in time order (for TrackRun).
struct RunScans {
  std::vector<const LaserScan*> before;  ///< robot still, before the run (at least one)
  std::vector<const LaserScan*> during;  ///< after t_start, before t_end
  std::vector<const LaserScan*> after;   ///< robot still, after the run (may be empty: then the last chained pose)
  std::int64_t t_start_ns = 0, t_end_ns = 0;  ///< the run's first and last wheel sample (both still)
};

struct TrackOptions {
  Pose2 mount;  ///< axle_T_lidar: the lidar's pose in the robot frame (axle midpoint, x forward)
  MatchOptions match;
  double keyframe_distance_m = 0.5;  ///< a scan this far from its keyframe becomes the next one
  double keyframe_angle_rad = 0.5;   ///< ... or turned this much
  double keyframe_overlap = 0.7;     ///< ... or pairing fewer of its points than this
  double min_end_overlap = 0.5;      ///< the end pairs at least this fraction with the reference, else goes via the keyframe
  std::size_t min_pairs = 30;        ///< fewer pairs: the registration failed
  double max_dilution = 5.0;         ///< UndeterminedDirections threshold
  /// Still scans (nearest the run) averaged into the model every still scan
  /// is registered against, to tell a small move from noise.
  std::size_t still_model_scans = 5;
  /// A still scan registered farther than this from that model (and than 4
  /// of its standard deviations) was taken from another pose.
  double still_min_move_m = 0.002;
  double still_min_turn_rad = 0.001;
  /// A still scan whose ranges differ from those of the still scan nearest
  /// the run by more than this (median over the beams) was taken from
  /// another pose: the robot was moved while its wheels stood still (carried
  /// back to the start, nudged). Each still scan is compared with the one
  /// nearest the run, not with its neighbour, so a slow carry is caught too.
  double still_moved_m = 0.03;
  /// Moving scans whose time_increment is set are deskewed: each beam moved
  /// to where the lidar was at the scan's first ray (its time), by the wheel
  /// odometry's motion over the sweep (laser_scan.hpp, Deskew).
  bool deskew = true;
  /// Still scans kept before a run (the ones nearest it): bounds the memory
  /// of a long standstill.
  std::size_t max_still_scans = 400;
  /// Empty when valid, else a message naming the bad field.
  std::string Validate() const;
};

struct TrackResult {
  /// The axle midpoint's pose relative to its pose at t_start, heading
  /// unwrapped, at the still scans, t_start, every chained scan, t_end; times increasing.
  std::vector<StampedPose> poses;
  Pose2 end;                              ///< at t_end
  std::array<double, 9> end_covariance{};  ///< of `end` (x, y, heading; row-major)
  /// Scatter of single still scans about the average of the few nearest the
  /// run (standard deviation per axis and of heading), over the kept still
  /// scans of both sides.
  double still_sd_xy_m = 0.0, still_sd_theta_rad = 0.0;
  std::size_t still_before = 0, still_after = 0, keyframes = 1, chained = 0;
  std::size_t still_moved = 0;     ///< times the robot was moved while its wheels stood still
  /// When it was moved: the first scan from another pose, counted outwards
  /// from the run (before the run: the last such scan; after: the first).
  std::int64_t moved_before_ns = 0, moved_after_ns = 0;
  /// The stretches whose scans were averaged (the robot still by the wheels
  /// and by the scans): first and last scan time before and after the run
  /// (after: 0, 0 when no scan came after it).
  std::int64_t still_before_from_ns = 0, still_before_to_ns = 0, still_after_from_ns = 0, still_after_to_ns = 0;
  bool end_direct = false;         ///< end registered against the reference (not via a keyframe)
  double max_residual_sd_m = 0.0;  ///< worst registration residual of the run
  std::size_t registrations = 0, iterations = 0;  ///< ICP calls and their Gauss-Newton iterations
};

/// A registration that left a direction undetermined (corridor, walls out of range).
class DegenerateScene : public std::runtime_error {
 public:
  DegenerateScene(std::int64_t t_ns, std::vector<std::string> directions, const std::string& what)
      : std::runtime_error(what), t_ns_(t_ns), directions_(std::move(directions)) {}
  std::int64_t t_ns() const { return t_ns_; }
  const std::vector<std::string>& directions() const { return directions_; }

 private:
  std::int64_t t_ns_;
  std::vector<std::string> directions_;
};

/// A scan that could not be registered (too few pairs).
class RegistrationFailed : public std::runtime_error {
 public:
  RegistrationFailed(std::int64_t t_ns, const std::string& what) : std::runtime_error(what), t_ns_(t_ns) {}
  std::int64_t t_ns() const { return t_ns_; }

 private:
  std::int64_t t_ns_;
};

/// Follows one run scan by scan, in time order (memory: two scan models,
/// the still scans before the run (at most max_still_scans), the still
/// average after it, a few still scans and one pose per scan).
/// `odometry(t)`: the wheel odometry's axle pose at time t in any fixed frame
/// (only increments are used, as predictions); it must outlive the tracker.
class RunTracker {
 public:
  RunTracker(const RunWindow& window, const std::function<Pose2(std::int64_t)>& odometry, const TrackOptions& options);
  ~RunTracker();
  RunTracker(RunTracker&&) noexcept;
  RunTracker& operator=(RunTracker&&) noexcept;
  const RunWindow& window() const;
  /// Takes a scan in [still_from, still_to] (others are ignored). Throws
  /// DegenerateScene, RegistrationFailed.
  void Add(const LaserScan& scan);
  /// The run's poses. Throws DegenerateScene, RegistrationFailed (also when
  /// no scan came while the robot stood still before the run).
  TrackResult Finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// RunTracker over lists of scans. Throws InvalidOptions, DegenerateScene,
/// RegistrationFailed.
TrackResult TrackRun(const RunScans& scans, const std::function<Pose2(std::int64_t)>& odometry,
                     const TrackOptions& options);

}  // namespace umbmark::scan
