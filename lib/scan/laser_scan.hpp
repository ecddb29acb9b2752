// A planar laser scan as sensor_msgs/msg/LaserScan holds it (beam i at
// angle_min + i * angle_increment in the sensor frame, x forward, y left),
// and the per-beam average of scans taken from one pose. A range that is
// NaN, infinite, or outside [range_min, range_max] is no return (REP 117:
// +inf = nothing within range, -inf = too close, NaN = invalid); such a
// beam is simply absent.
#pragma once

#include <cstdint>
#include <vector>

namespace umbmark::scan {

struct LaserScan {
  std::int64_t t_ns = 0;  ///< time of the scan
  double angle_min = 0.0, angle_increment = 0.0;
  double range_min = 0.0, range_max = 0.0;
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

/// ScanAverager over a list. Throws std::invalid_argument when the list is
/// empty or the layouts differ.
LaserScan AverageScans(const std::vector<const LaserScan*>& scans);

}  // namespace umbmark::scan
