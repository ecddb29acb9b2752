// Laser scans: valid beams and still-scan averaging (see laser_scan.hpp).
#include "scan/laser_scan.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace umbmark::scan {

std::size_t LaserScan::ValidCount() const {
  std::size_t n = 0;
  for (std::size_t i = 0; i < ranges.size(); ++i) n += Valid(i) ? 1 : 0;
  return n;
}

void ScanAverager::Add(const LaserScan& s) {
  if (count_ == 0) {
    first_ = s;
    sum_.assign(s.ranges.size(), 0.0);
    valid_.assign(s.ranges.size(), 0);
  } else if (s.ranges.size() != first_.ranges.size() || std::abs(s.angle_min - first_.angle_min) > 1e-9 ||
             std::abs(s.angle_increment - first_.angle_increment) > 1e-12) {
    throw std::invalid_argument("scans with different beam layouts cannot be averaged");
  }
  for (std::size_t i = 0; i < s.ranges.size(); ++i)
    if (s.Valid(i)) {
      sum_[i] += s.ranges[i];
      ++valid_[i];
    }
  ++count_;
}

LaserScan ScanAverager::Mean() const {
  if (count_ == 0) throw std::invalid_argument("no scans to average");
  LaserScan out = first_;
  for (std::size_t i = 0; i < out.ranges.size(); ++i) {
    out.ranges[i] = 2 * static_cast<std::size_t>(valid_[i]) >= count_ && valid_[i] > 0
                        ? static_cast<float>(sum_[i] / static_cast<double>(valid_[i]))
                        : std::numeric_limits<float>::quiet_NaN();
  }
  return out;
}

LaserScan AverageScans(const std::vector<const LaserScan*>& scans) {
  ScanAverager a;
  for (const LaserScan* s : scans) a.Add(*s);
  return a.Mean();
}

}  // namespace umbmark::scan
