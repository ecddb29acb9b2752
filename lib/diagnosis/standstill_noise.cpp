// The ground truth's noise from sample-to-sample differences inside
// standstills (standstill_noise.hpp).
#include "diagnosis/standstill_noise.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "core/angles.hpp"

namespace umbmark::diag {

std::string StandstillNoiseOptions::Check() const {
  if (!(settle_s >= 0.0)) return fmt::format("settle_s = {} must be >= 0", settle_s);
  if (lead_samples < 0) return fmt::format("lead_samples = {} must be >= 0", lead_samples);
  if (min_differences < 3) return fmt::format("min_differences = {} must be >= 3", min_differences);
  return {};
}

namespace {

/// 1.4826 x the median absolute deviation from the median: the sd of
/// normal values.
double RobustSd(std::vector<double> v) {
  if (v.empty()) return 0.0;
  auto median = [](std::vector<double>& x) {
    const std::size_t m = x.size() / 2;
    std::nth_element(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(m), x.end());
    const double hi = x[m];
    if (x.size() % 2 == 1) return hi;
    return 0.5 * (hi + *std::max_element(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(m)));
  };
  const double med = median(v);
  for (double& x : v) x = std::abs(x - med);
  return 1.482602218505602 * median(v);
}

/// Appends the differences of one standstill of `run`: samples lo..hi
/// (every interval between them still).
void StandstillDifferences(const DiagRun& run, std::size_t lo, std::size_t hi, const StandstillNoiseOptions& o,
                           std::vector<double>& dxy, std::vector<double>& dth, bool& used) {
  const bool after_motion = lo > 0;  // the run's first samples follow no stop
  std::size_t first = lo;
  if (after_motion)
    while (first < hi && run.t[first] - run.t[lo] < o.settle_s) ++first;
  const bool before_motion = hi + 1 < run.t.size();
  const std::size_t lead = before_motion ? static_cast<std::size_t>(o.lead_samples) : 0;
  if (hi < first + lead + 1) return;
  const std::size_t last = hi - lead;
  for (std::size_t i = first; i < last; ++i) {
    if (!run.has_gt[i] || !run.has_gt[i + 1]) continue;
    dxy.push_back(run.gt[i + 1].x - run.gt[i].x);
    dxy.push_back(run.gt[i + 1].y - run.gt[i].y);
    dth.push_back(WrapAngle(run.gt[i + 1].theta - run.gt[i].theta));
    used = true;
  }
}

}  // namespace

StandstillNoise MeasureStandstillNoise(const CampaignData& c, const StandstillNoiseOptions& o) {
  std::vector<double> dxy, dth;
  StandstillNoise out;
  for (const DiagRun& run : c.runs) {
    if (run.endpoint) continue;
    const std::size_t n = run.t.size();
    std::size_t i = 0;
    while (i + 1 < n) {
      if (i >= run.interval_class.size() || run.interval_class[i] >= 0) {
        ++i;
        continue;
      }
      std::size_t j = i;
      while (j < run.interval_class.size() && j + 1 < n && run.interval_class[j] < 0) ++j;
      bool used = false;
      StandstillDifferences(run, i, j, o, dxy, dth, used);
      out.standstills += used ? 1 : 0;
      i = j;
    }
  }
  out.differences = static_cast<int>(dth.size());
  if (out.differences < o.min_differences) return out;
  out.measured = true;
  out.sigma_xy_m = RobustSd(std::move(dxy)) / std::sqrt(2.0);
  out.sigma_theta_rad = RobustSd(std::move(dth)) / std::sqrt(2.0);
  return out;
}

}  // namespace umbmark::diag
