// The ground truth's noise from differences inside standstills, at the
// plateau of the structure function (standstill_noise.hpp).
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
  if (max_lag < 1) return fmt::format("max_lag = {} must be >= 1", max_lag);
  if (!(plateau_tolerance > 0.0)) return fmt::format("plateau_tolerance = {} must be > 0", plateau_tolerance);
  if (!(floor_xy_m >= 0.0)) return fmt::format("floor_xy_m = {} must be >= 0", floor_xy_m);
  if (!(floor_theta_rad >= 0.0)) return fmt::format("floor_theta_rad = {} must be >= 0", floor_theta_rad);
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

/// The sd of the values about their mean (n - 1 degrees of freedom).
double Sd(const std::vector<double>& v) {
  if (v.size() < 2) return 0.0;
  double mean = 0.0;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  double ss = 0.0;
  for (double x : v) ss += (x - mean) * (x - mean);
  return std::sqrt(ss / static_cast<double>(v.size() - 1));
}

/// The samples of one standstill that count: run samples first..last.
struct Stretch {
  const DiagRun* run = nullptr;
  std::size_t first = 0, last = 0;
};

/// The usable stretch of the standstill lo..hi of `run` (every interval
/// between them still), or an empty one.
Stretch UsableStretch(const DiagRun& run, std::size_t lo, std::size_t hi, const StandstillNoiseOptions& o) {
  const bool after_motion = lo > 0;  // the run's first samples follow no stop
  std::size_t first = lo;
  if (after_motion)
    while (first < hi && run.t[first] - run.t[lo] < o.settle_s) ++first;
  const bool before_motion = hi + 1 < run.t.size();
  const std::size_t lead = before_motion ? static_cast<std::size_t>(o.lead_samples) : 0;
  if (hi < first + lead + 1) return {};
  return {&run, first, hi - lead};
}

std::vector<Stretch> Standstills(const CampaignData& c, const StandstillNoiseOptions& o) {
  std::vector<Stretch> out;
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
      if (Stretch s = UsableStretch(run, i, j, o); s.run) out.push_back(s);
      i = j;
    }
  }
  return out;
}

/// Differences over `lag` samples inside the stretches.
void LagDifferences(const std::vector<Stretch>& st, std::size_t lag, std::vector<double>& dxy, std::vector<double>& dth,
                    int* standstills) {
  dxy.clear();
  dth.clear();
  for (const Stretch& s : st) {
    const DiagRun& run = *s.run;
    bool used = false;
    for (std::size_t i = s.first; i + lag <= s.last; ++i) {
      if (!run.has_gt[i] || !run.has_gt[i + lag]) continue;
      dxy.push_back(run.gt[i + lag].x - run.gt[i].x);
      dxy.push_back(run.gt[i + lag].y - run.gt[i].y);
      dth.push_back(WrapAngle(run.gt[i + lag].theta - run.gt[i].theta));
      used = true;
    }
    if (standstills && used) ++*standstills;
  }
}

/// sigma(k) = sd / sqrt 2 of the differences over k samples (xy, th), for
/// k = 1, 2, 4, ... up to max_lag while each has min_differences (robust
/// ones with StandstillNoiseOptions::robust); the robust scale beside them
/// (xy_other, th_other).
struct StructureFunction {
  std::vector<int> lags;
  std::vector<double> xy, th, xy_other, th_other;
};

/// The plateau of sigma(k): sigma at the doubled lag 2k of the first k
/// whose doubling raises it by at most `tol` (the value reached once it
/// levels off: at k itself an AR(1) capture noise of r(1) = 0.8 would still
/// be 9 % short); else the last lag (no plateau, or a single lag).
void Plateau(const std::vector<int>& lags, const std::vector<double>& s, double tol, double& sigma, int& lag,
             bool& plateau) {
  std::size_t i = 0;
  while (i + 1 < s.size() && s[i + 1] > (1.0 + tol) * s[i]) ++i;
  plateau = i + 1 < s.size();
  if (plateau) ++i;
  sigma = s[i];
  lag = lags[i];
}

}  // namespace

StandstillNoise MeasureStandstillNoise(const CampaignData& c, const StandstillNoiseOptions& o) {
  StandstillNoise out;
  const std::vector<Stretch> st = Standstills(c, o);
  StructureFunction sf;
  std::vector<double> dxy, dth;
  for (int lag = 1; lag <= o.max_lag; lag *= 2) {
    LagDifferences(st, static_cast<std::size_t>(lag), dxy, dth, lag == 1 ? &out.standstills : nullptr);
    if (lag == 1) out.differences = static_cast<int>(dth.size());
    if (static_cast<int>(dth.size()) < o.min_differences) break;
    sf.lags.push_back(lag);
    const double rxy = RobustSd(dxy) / std::sqrt(2.0), rth = RobustSd(dth) / std::sqrt(2.0);
    const double vxy = Sd(dxy) / std::sqrt(2.0), vth = Sd(dth) / std::sqrt(2.0);
    sf.xy.push_back(o.robust ? rxy : vxy);
    sf.th.push_back(o.robust ? rth : vth);
    sf.xy_other.push_back(rxy);
    sf.th_other.push_back(rth);
  }
  if (sf.lags.empty()) return out;
  out.measured = true;
  out.lag1_sigma_xy_m = sf.xy.front();
  out.lag1_sigma_theta_rad = sf.th.front();
  Plateau(sf.lags, sf.xy, o.plateau_tolerance, out.sigma_xy_m, out.lag_xy, out.plateau_xy);
  Plateau(sf.lags, sf.th, o.plateau_tolerance, out.sigma_theta_rad, out.lag_theta, out.plateau_theta);
  auto at = [&](const std::vector<double>& v, int lag) {
    for (std::size_t i = 0; i < sf.lags.size(); ++i)
      if (sf.lags[i] == lag) return v[i];
    return v.back();
  };
  out.robust_sigma_xy_m = at(sf.xy_other, out.lag_xy);
  out.robust_sigma_theta_rad = at(sf.th_other, out.lag_theta);
  out.floored_xy = out.sigma_xy_m < o.floor_xy_m;
  out.floored_theta = out.sigma_theta_rad < o.floor_theta_rad;
  out.sigma_xy_m = std::max(out.sigma_xy_m, o.floor_xy_m);
  out.sigma_theta_rad = std::max(out.sigma_theta_rad, o.floor_theta_rad);
  return out;
}

}  // namespace umbmark::diag
