// The lidar's own motion from a drive, as relative-pose measurements between
// keyframe scans (the input of the joint fit, lidar_joint.hpp). Every scan is
// registered against the current keyframe by point-to-line ICP
// (scan/scan_matcher.hpp) from a constant-velocity guess in the lidar's own
// frame, so no mounting pose and no wheel model is needed to track; a scan
// becomes the next keyframe when it is keyframe_distance_m or
// keyframe_angle_rad from the last one, pairs too few of its points, or
// keyframe_max_s has passed, and that registration is one measurement:
//
//     keyframe a  --lidar_a_T_lidar_b-->  keyframe b      (scan frames as recorded)
//
// with its covariance (residual variance times (J^T J)^-1). A sweeping
// scan (time_increment set) is first deskewed to where the lidar was at its
// first ray, by the lidar's own tracked velocity. The measurement
// is the mean of the registration both ways (b onto a, a onto b), which
// cancels most of the bias of point-to-line ICP towards its model. A measurement the
// scene does not determine (a corridor's length) is kept, marked with the
// direction it leaves open, in the room's frame (the first scan's), so the
// caller can drop it and name the direction.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/pose2.hpp"
#include "scan/laser_scan.hpp"
#include "scan/scan_matcher.hpp"

namespace umbmark::calibration {

/// One relative-pose measurement of the lidar between two keyframe scans.
struct ScanPair {
  std::int64_t t_a_ns = 0, t_b_ns = 0;  ///< header stamps of the two scans
  Pose2 lidar_a_T_lidar_b;              ///< the registration, in the scan frames as recorded
  std::array<double, 9> covariance{};   ///< of (x, y, theta) [m^2, rad^2], row-major
  std::size_t pairs = 0;                ///< point pairs of the registration
  /// Keyframe a's pose in the first scan's frame (the chain), for naming a
  /// direction in the room.
  Pose2 lidar0_T_lidar_a;
  /// Directions the scene leaves open ("along x", "along y", "heading", in
  /// scan a's frame), worst first; empty when well posed.
  std::vector<std::string> undetermined;
  /// Angle of the worst open direction in the first scan's frame [rad]
  /// (a corridor's axis); NaN when well posed or when it is the heading.
  double open_direction_rad = 0.0;
};

/// Keyframe and registration settings. Defaults: 0.4 m / 0.6 rad keyframes
/// (each measurement turns enough to weigh the wheelbase while two scans
/// still overlap), a new keyframe at least every 3 s, the scan matcher's
/// defaults.
struct PairOptions {
  double keyframe_distance_m = 0.4;  ///< new keyframe this far from the last [m]
  double keyframe_angle_rad = 0.6;   ///< or turned this much [rad]
  double keyframe_max_s = 3.0;       ///< or this long after it [s]
  double min_paired_fraction = 0.6;  ///< or when fewer of the scan's points pair
  double max_dilution = 5.0;         ///< registration dilution of precision above which a direction is open
  std::size_t min_points = 30;       ///< a registration with fewer pairs is lost (tracking restarts)
  /// Each measurement the mean of the registration both ways (b onto a and
  /// a onto b): cancels most of point-to-line ICP's bias towards its model
  /// (lidar_pairs.cpp, Symmetrised). Costs one registration per keyframe.
  bool symmetric = true;
  /// A scan whose beams are timed (time_increment != 0) is deskewed to its
  /// first ray (scan/laser_scan.hpp, Deskew) by the tracked velocity: first
  /// the last step's, then, registered, the step it gives (a second pass,
  /// when that moves the sweep's end by over 0.5 mm or 0.5 mrad: a single
  /// pass feeds its own error back into the next scan's velocity and
  /// oscillates).
  bool deskew = true;
  /// The scan matcher's defaults, but no pairs with the background beside an
  /// occluder's edge: on 30 simulated drives in a furnished room (seeds
  /// 1-30) the translations read 1.8e-4 m/m long with those pairs and
  /// 0.8e-4 without (bench/bench_lidar_pairs.cpp).
  scan::MatchOptions match{.skip_shadow_edges = true};
  /// Empty when valid, else a message naming the bad field.
  std::string Validate() const;
};

struct PairResult {
  std::vector<ScanPair> pairs;   ///< in time order, each b the next one's a unless tracking was lost
  std::size_t scans = 0;         ///< scans registered
  std::size_t lost = 0;          ///< registrations that failed (tracking restarted at that scan)
  Pose2 lidar0_T_lidar_last;     ///< the chain's last scan in the first scan's frame
};

/// Registers `scans` (header-stamp order) into keyframe measurements. Throws
/// InvalidOptions for bad options. A scan with fewer than min_points valid
/// beams restarts tracking (counted in `lost`).
PairResult RegisterScanPairs(const std::vector<scan::LaserScan>& scans, const PairOptions& options = {});

}  // namespace umbmark::calibration
