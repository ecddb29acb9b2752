// The two readings of the contract's stop (see stop_model.hpp).
#include "diagnosis/stop_model.hpp"

#include <cmath>

#include "core/errors.hpp"

namespace umbmark::diag {

const char* StopModelToString(StopModel m) {
  switch (m) {
    case StopModel::kWheelEdge: return "each wheel on its tick";
    case StopModel::kBody: return "robot stopped on its odometry (one wheel on its tick, the other anywhere in its tick)";
  }
  return "?";
}

bool HasJointStops(const CampaignData& c) {
  if (!(c.tick_left_m > 0.0 && c.tick_right_m > 0.0)) return false;
  for (const DiagRun& r : c.runs)
    for (std::size_t i = 0; i < r.stop_dir_left.size(); ++i)
      if (r.stop_dir_left[i] != 0 && r.stop_dir_right[i] != 0) return true;
  return false;
}

CampaignData WithBodyStops(const CampaignData& c) {
  if (c.stop_model != StopModel::kWheelEdge) throw InvalidOptions("WithBodyStops: the campaign is already in the body reading");
  CampaignData out = c;
  out.stop_model = StopModel::kBody;
  const double tl = c.tick_left_m, tr = c.tick_right_m;
  const double sd_l = tl * std::sqrt(BodyStopMoments::kVar), sd_r = tr * std::sqrt(BodyStopMoments::kVar);
  for (DiagRun& r : out.runs) {
    if (r.endpoint) continue;
    bool changed = false;
    for (std::size_t i = 0; i < r.t.size(); ++i) {
      const int sl = r.stop_dir_left[i], sr = r.stop_dir_right[i];
      if (sl == 0 || sr == 0) continue;
      // The kWheelEdge phase is u = 0; kBody's mean is u = 1/4 (e = s t (u - 1/4)).
      r.left[i] += sl * tl * BodyStopMoments::kMean;
      r.right[i] += sr * tr * BodyStopMoments::kMean;
      r.q_sd_left[i] = sd_l;
      r.q_sd_right[i] = sd_r;
      r.q_cov_lr[i] = sl * sr * tl * tr * BodyStopMoments::kCov;
      changed = true;
    }
    if (changed) AnnotateRun(r);
  }
  return out;
}

std::pair<double, double> DrawBodyStop(double coin, double u, int s_left, int s_right, double tick_left_m,
                                       double tick_right_m) {
  const double ul = coin < 0.5 ? 0.0 : u, ur = coin < 0.5 ? u : 0.0;
  return {s_left * tick_left_m * (ul - BodyStopMoments::kMean), s_right * tick_right_m * (ur - BodyStopMoments::kMean)};
}

}  // namespace umbmark::diag
