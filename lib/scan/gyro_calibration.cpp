// Gyro bias and scale against scan-registered headings (see gyro_calibration.hpp).
#include "scan/gyro_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace umbmark::scan {

double IntegrateRate(const std::vector<GyroSample>& s, double bias, std::int64_t t0, std::int64_t t1) {
  if (s.size() < 2 || t1 <= t0) return 0.0;
  auto at = [&](std::int64_t t) {
    auto it = std::lower_bound(s.begin(), s.end(), t, [](const GyroSample& g, std::int64_t v) { return g.t_ns < v; });
    if (it == s.begin()) return it->rate_rad_s;
    if (it == s.end()) return s.back().rate_rad_s;
    const GyroSample& b = *it;
    const GyroSample& a = *(it - 1);
    const double u = static_cast<double>(t - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns);
    return a.rate_rad_s + u * (b.rate_rad_s - a.rate_rad_s);
  };
  double sum = 0.0;
  std::int64_t pt = t0;
  double pr = at(t0);
  auto it = std::upper_bound(s.begin(), s.end(), t0, [](std::int64_t v, const GyroSample& g) { return v < g.t_ns; });
  for (; it != s.end() && it->t_ns < t1; ++it) {
    sum += 0.5 * (pr + it->rate_rad_s) * static_cast<double>(it->t_ns - pt) * 1e-9;
    pt = it->t_ns;
    pr = it->rate_rad_s;
  }
  const double r1 = at(t1);
  sum += 0.5 * (pr + r1) * static_cast<double>(t1 - pt) * 1e-9;
  return sum - bias * static_cast<double>(t1 - t0) * 1e-9;
}

GyroCalibration CalibrateGyro(const std::vector<GyroSample>& samples,
                              const std::vector<std::pair<std::int64_t, std::int64_t>>& still,
                              const std::vector<GyroRun>& runs) {
  GyroCalibration c;
  double sum = 0.0, sum2 = 0.0;
  for (const auto& [a, b] : still) {
    auto it = std::lower_bound(samples.begin(), samples.end(), a,
                               [](const GyroSample& g, std::int64_t v) { return g.t_ns < v; });
    for (; it != samples.end() && it->t_ns <= b; ++it) {
      sum += it->rate_rad_s;
      sum2 += it->rate_rad_s * it->rate_rad_s;
      ++c.still_samples;
    }
  }
  if (c.still_samples == 0) throw std::invalid_argument("no gyro reading while the robot stands still");
  const double n = static_cast<double>(c.still_samples);
  c.bias_rad_s = sum / n;
  c.bias_sd_rad_s = n > 1 ? std::sqrt(std::max(0.0, (sum2 - n * c.bias_rad_s * c.bias_rad_s) / (n - 1.0)) / n) : 0.0;
  double gd = 0.0, dd = 0.0;
  std::vector<double> g;
  for (const GyroRun& r : runs) {
    g.push_back(IntegrateRate(samples, c.bias_rad_s, r.t_start_ns, r.t_end_ns));
    gd += g.back() * r.scan_heading_change_rad;
    dd += r.scan_heading_change_rad * r.scan_heading_change_rad;
  }
  if (!(dd > 0.01)) throw std::invalid_argument("the runs do not turn: no gyro scale can be found");
  c.scale = gd / dd;
  for (double v : g) c.gyro_heading_change_rad.push_back(v / c.scale);
  return c;
}

}  // namespace umbmark::scan
