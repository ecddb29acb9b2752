// A planar laser scan as sensor_msgs/msg/LaserScan holds it (beam i at
// angle_min + i * angle_increment in the sensor frame, x forward, y left),
// and the per-beam average of scans taken from one pose. A range that is
// NaN, infinite, or outside [range_min, range_max] is no return (REP 117:
// +inf = nothing within range, -inf = too close, NaN = invalid); such a
// beam is simply absent.
#pragma once

#include <cstdint>
#include <vector>

#include "core/pose2.hpp"

namespace umbmark::scan {

struct LaserScan {
  std::int64_t t_ns = 0;  ///< time of the scan: of its first ray (the earliest) once the clock is known
  double angle_min = 0.0, angle_increment = 0.0;
  double range_min = 0.0, range_max = 0.0;
  /// Seconds between two beams (beam i at i * time_increment after beam 0;
  /// negative: the sweep runs from the last beam to the first); 0 when the
  /// driver does not say (the scan is then taken as instantaneous).
  double time_increment = 0.0;
  double scan_time = 0.0;  ///< seconds between scans (0: not given)
  std::vector<float> ranges;

  /// True when beam i returned a usable range.
  bool Valid(std::size_t i) const {
    const double r = ranges[i];
    return r == r && r >= range_min && r <= range_max && r > 0.0 && r < 1e30;
  }
  std::size_t ValidCount() const;
};

/// Per-beam mean of the valid ranges of scans taken from one pose, added one
/// at a time (memory: one scan's worth however many are added). A beam valid
/// in fewer than half of them is no return (NaN).
class ScanAverager {
 public:
  /// Throws std::invalid_argument when the beam layout differs from the first scan's.
  void Add(const LaserScan& scan);
  std::size_t count() const { return count_; }
  /// The mean scan (the first scan's time and layout); count() must be > 0.
  LaserScan Mean() const;

 private:
  LaserScan first_;
  std::vector<double> sum_;
  std::vector<std::uint32_t> valid_;
  std::size_t count_ = 0;
};

/// A scan from a lidar mounted upside down (its z axis pointing down), as
/// the same lidar upright would see it: the beam at angle a is at -a. The
/// ranges are reversed so that the angles still increase.
void MirrorBeams(LaserScan& scan);

/// Seconds from the scan's first (earliest) ray to beam i.
inline double BeamTime(const LaserScan& s, std::size_t i) {
  const double k = s.time_increment >= 0.0 ? static_cast<double>(i)
                                            : static_cast<double>(i) - static_cast<double>(s.ranges.size() - 1);
  return k * s.time_increment;
}

/// The scan as taken from where the lidar was at its first ray: each beam's
/// point moved by `motion(t)`, the lidar's pose at t seconds after the first
/// ray relative to its pose then (lidar0_T_lidar), and the points put back
/// on the scan's own beam angles (range interpolated between the two moved
/// points around each beam angle when they lie on one surface, within 5 cm;
/// else the nearer one; no return where neither moved point is near). A scan
/// with time_increment 0 is returned as it is.
LaserScan Deskew(const LaserScan& scan, const Pose2& motion_over_sweep);

/// Median |range difference| over the beams both scans returned: a few mm
/// for two scans from one pose (1 cm range noise), centimetres when the
/// lidar moved between them; infinity when the layouts differ or no beam
/// returned in both.
double MedianRangeChange(const LaserScan& a, const LaserScan& b);

/// ScanAverager over a list. Throws std::invalid_argument when the list is
/// empty or the layouts differ.
LaserScan AverageScans(const std::vector<const LaserScan*>& scans);

}  // namespace umbmark::scan
