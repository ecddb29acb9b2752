// The campaign's speeds and distances (see campaign_scale.hpp).
#include "diagnosis/campaign_scale.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace umbmark::diag {

namespace {
double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}
}  // namespace

effects::CampaignScale CampaignScaleOf(const CampaignData& c, double negligible) {
  effects::CampaignScale out;
  out.negligible = negligible;
  // Below these a sample interval is still (encoder quantisation).
  constexpr double kMinSpeed = 1e-3, kMinRate = 1e-3;
  const double b = c.robot.wheelbase_m;
  std::vector<double> speeds, rates, lengths;
  for (const DiagRun& r : c.runs) {
    if (r.endpoint) continue;
    double length = 0.0;
    for (std::size_t i = 0; i + 1 < r.t.size() && i + 1 < r.left.size() && i + 1 < r.right.size(); ++i) {
      const bool moving = i < r.interval_class.size() && r.interval_class[i] >= 0;
      const double dl = r.left[i + 1] - r.left[i], dr = r.right[i + 1] - r.right[i], dt = r.t[i + 1] - r.t[i];
      if (!moving) {
        if (length > 0.0) lengths.push_back(length);
        length = 0.0;
        continue;
      }
      // Speeds and lengths of straights and arcs, rates of spot turns and arcs.
      const bool turn = r.interval_class[i] == static_cast<signed char>(sim::MotionClass::kTurn);
      const bool arc = r.interval_class[i] == static_cast<signed char>(sim::MotionClass::kArc);
      if (!turn) length += 0.5 * (std::abs(dl) + std::abs(dr));
      if (!(dt > 0.0)) continue;
      if (const double v = std::abs(dl + dr) / (2.0 * dt); !turn && v > kMinSpeed) speeds.push_back(v);
      if (b > 0.0 && (turn || arc))
        if (const double w = std::abs(dr - dl) / (b * dt); w > kMinRate) rates.push_back(w);
    }
    if (length > 0.0) lengths.push_back(length);
  }
  if (!speeds.empty()) out.speed_mps = Median(std::move(speeds));
  if (!rates.empty()) out.turn_rate_radps = Median(std::move(rates));
  if (!lengths.empty()) out.motion_length_m = Median(std::move(lengths));
  return out;
}

}  // namespace umbmark::diag
