// Laser scans: valid beams and still-scan averaging (see laser_scan.hpp).
#include "scan/laser_scan.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/angles.hpp"

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

void MirrorBeams(LaserScan& s) {
  if (s.ranges.empty()) return;
  const double last = s.angle_min + static_cast<double>(s.ranges.size() - 1) * s.angle_increment;
  s.angle_min = -last;
  std::reverse(s.ranges.begin(), s.ranges.end());
  s.time_increment = -s.time_increment;  // the first ray is now at the other end
}

// Constant velocity over the sweep: the motion at u of the sweep is u times
// the whole (exact to O(motion^2), a few tenths of a mm over 0.1 s).
LaserScan Deskew(const LaserScan& s, const Pose2& whole) {
  const std::size_t n = s.ranges.size();
  if (s.time_increment == 0.0 || n < 2) return s;
  const double sweep = std::abs(s.time_increment) * static_cast<double>(n - 1);
  // Moved points: bearing and range, per beam (NaN: no return).
  std::vector<double> bearing(n, std::numeric_limits<double>::quiet_NaN()), range(n, bearing[0]);
  for (std::size_t i = 0; i < n; ++i) {
    if (!s.Valid(i)) continue;
    const double u = BeamTime(s, i) / sweep;
    const double a = s.angle_min + static_cast<double>(i) * s.angle_increment, r = s.ranges[i];
    const double th = u * whole.theta, c = std::cos(th), sn = std::sin(th);
    const double px = r * std::cos(a), py = r * std::sin(a);
    const double x = u * whole.x + c * px - sn * py, y = u * whole.y + sn * px + c * py;
    bearing[i] = std::atan2(y, x);
    range[i] = std::hypot(x, y);
  }
  LaserScan out = s;
  out.time_increment = 0.0;
  const double inc = s.angle_increment;
  // Each beam angle between the moved bearings of two neighbouring beams,
  // searched over as many beams as the sweep turned (and 0.1 rad more).
  const auto window = static_cast<std::size_t>(std::ceil((std::abs(whole.theta) + 0.1) / std::abs(inc))) + 2;
  for (std::size_t j = 0; j < n; ++j) {
    const double g = s.angle_min + static_cast<double>(j) * inc;
    float best = std::numeric_limits<float>::quiet_NaN();
    for (std::size_t k = j >= window ? j - window : 0; k + 1 < n && k <= j + window; ++k) {
      if (std::isnan(range[k]) || std::isnan(range[k + 1])) continue;
      const double d0 = WrapAngle(bearing[k] - g), d1 = WrapAngle(bearing[k + 1] - g);
      if ((d0 > 0.0) == (d1 > 0.0) && d0 != 0.0) continue;  // g not between them
      const double span = d0 - d1;
      const double w = std::abs(span) < 1e-12 ? 0.0 : d0 / span;
      const bool one_surface = std::abs(range[k] - range[k + 1]) < 0.05;
      const double r = one_surface ? range[k] + w * (range[k + 1] - range[k]) : (w < 0.5 ? range[k] : range[k + 1]);
      best = static_cast<float>(r);
      break;
    }
    out.ranges[j] = best;
  }
  return out;
}

// Median |range difference| over the beams both scans returned: a few mm
// for two scans from one pose, far more when the robot was moved between them.
double MedianRangeChange(const LaserScan& a, const LaserScan& b) {
  if (a.ranges.size() != b.ranges.size()) return std::numeric_limits<double>::infinity();
  std::vector<double> d;
  d.reserve(a.ranges.size());
  for (std::size_t i = 0; i < a.ranges.size(); ++i)
    if (a.Valid(i) && b.Valid(i)) d.push_back(std::abs(static_cast<double>(a.ranges[i]) - b.ranges[i]));
  if (d.empty()) return std::numeric_limits<double>::infinity();
  auto mid = d.begin() + static_cast<long>(d.size() / 2);
  std::nth_element(d.begin(), mid, d.end());
  return *mid;
}

LaserScan AverageScans(const std::vector<const LaserScan*>& scans) {
  ScanAverager a;
  for (const LaserScan* s : scans) a.Add(*s);
  return a.Mean();
}

}  // namespace umbmark::scan
