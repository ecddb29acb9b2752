// The scan clock against the wheels (see scan_clock.hpp).
#include "scan/scan_clock.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace umbmark::scan {

namespace {

// Pearson correlation of the scans' range changes with the wheels' motion
// over the same intervals shifted by `offset_s`.
double Correlation(const std::vector<ScanChange>& c, const WheelMotion& w, double offset_s) {
  const auto off = static_cast<std::int64_t>(std::llround(offset_s * 1e9));
  double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
  for (const auto& k : c) {
    const double x = k.median_change_m, y = w.At(k.t_ns + off) - w.At(k.t_prev_ns + off);
    sx += x;
    sy += y;
    sxx += x * x;
    syy += y * y;
    sxy += x * y;
  }
  const double n = static_cast<double>(c.size());
  const double vx = sxx - sx * sx / n, vy = syy - sy * sy / n;
  if (!(vx > 0.0) || !(vy > 0.0)) return 0.0;
  return (sxy - sx * sy / n) / std::sqrt(vx * vy);
}

}  // namespace

WheelMotion WheelMotion::FromTravel(const std::vector<std::int64_t>& t, const std::vector<double>& l,
                                    const std::vector<double>& r, double b, double lever) {
  WheelMotion w;
  w.t_ns = t;
  w.cumulative.assign(t.size(), 0.0);
  for (std::size_t k = 1; k < t.size(); ++k) {
    const double dl = l[k] - l[k - 1], dr = r[k] - r[k - 1];
    w.cumulative[k] = w.cumulative[k - 1] + 0.5 * std::abs(dl + dr) + lever * std::abs(dr - dl) / b;
  }
  return w;
}

double WheelMotion::At(std::int64_t t) const {
  if (t_ns.empty()) return 0.0;
  if (t <= t_ns.front()) return cumulative.front();
  if (t >= t_ns.back()) return cumulative.back();
  const auto k = static_cast<std::size_t>(std::upper_bound(t_ns.begin(), t_ns.end(), t) - t_ns.begin());
  const double u = static_cast<double>(t - t_ns[k - 1]) / static_cast<double>(t_ns[k] - t_ns[k - 1]);
  return cumulative[k - 1] + u * (cumulative[k] - cumulative[k - 1]);
}

std::string ClockOptions::Validate() const {
  if (!(search_s > 0.0)) return fmt::format("search_s = {}: must be > 0", search_s);
  if (!(coarse_step_s > 0.0) || coarse_step_s > search_s) return fmt::format("coarse_step_s = {}: must be in (0, search_s]", coarse_step_s);
  if (!(fine_step_s > 0.0) || fine_step_s > coarse_step_s) return fmt::format("fine_step_s = {}: must be in (0, coarse_step_s]", fine_step_s);
  if (!(min_correlation > 0.0 && min_correlation < 1.0)) return fmt::format("min_correlation = {}: must be in (0, 1)", min_correlation);
  return {};
}

ClockEstimate EstimateClockCoarse(const std::vector<ScanChange>& changes, const WheelMotion& wheels, const ClockOptions& o) {
  ClockEstimate e;
  if (changes.size() < 10 || wheels.t_ns.size() < 2) return e;
  const int steps = static_cast<int>(std::lround(o.search_s / o.coarse_step_s));
  double best = -2.0, at = 0.0;
  for (int i = -steps; i <= steps; ++i) {
    const double off = i * o.coarse_step_s, c = Correlation(changes, wheels, off);
    if (c > best) {
      best = c;
      at = off;
    }
  }
  const int fine = static_cast<int>(std::lround(o.coarse_step_s / o.fine_step_s));
  const double coarse = at;
  for (int i = -fine; i <= fine; ++i) {
    const double off = coarse + i * o.fine_step_s, c = Correlation(changes, wheels, off);
    if (c > best) {
      best = c;
      at = off;
    }
  }
  e.offset_s = at;
  e.correlation = best;
  e.determined = best >= o.min_correlation;
  return e;
}

FineClock RefineClock(const std::vector<HeadingTrack>& runs, const std::vector<std::int64_t>& run_start_ns,
                      const std::function<double(std::int64_t)>& heading, double window_s, double step_s) {
  FineClock f;
  const int steps = static_cast<int>(std::lround(window_s / step_s));
  double best = INFINITY;
  int best_i = 0;
  std::size_t n = 0;
  for (int i = -steps; i <= steps; ++i) {
    const auto off = static_cast<std::int64_t>(std::llround(i * step_s * 1e9));
    // Least squares scale of the odometry's heading, then the residual.
    double so = 0.0, ss = 0.0, oo = 0.0;
    n = 0;
    for (std::size_t r = 0; r < runs.size(); ++r) {
      const double h0 = heading(run_start_ns[r]);
      for (std::size_t k = 0; k < runs[r].t_ns.size(); ++k) {
        const double o = heading(runs[r].t_ns[k] + off) - h0, s = runs[r].scan_heading_rad[k];
        so += s * o;
        ss += s * s;
        oo += o * o;
        ++n;
      }
    }
    if (n == 0 || !(oo > 0.0)) return f;
    const double c = so / oo, sse = ss - c * so;
    if (sse < best) {
      best = sse;
      best_i = i;
    }
  }
  f.determined = std::abs(best_i) < steps;
  f.correction_s = f.determined ? best_i * step_s : 0.0;
  f.rms_rad = std::sqrt(std::max(0.0, best) / static_cast<double>(std::max<std::size_t>(1, n)));
  return f;
}

}  // namespace umbmark::scan
