// Physical plausibility of fitted effects (see plausibility.hpp).
#include "diagnosis/plausibility.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

namespace umbmark::diag {

std::string UnphysicalFit(const std::string& effect, const std::map<std::string, double>& params, int runs,
                          const std::map<std::string, double>& se) {
  auto get = [&](const char* k) {
    const auto it = params.find(k);
    return it == params.end() ? 0.0 : it->second;
  };
  const auto k_se = se.find("k");
  const bool scrub_negative =
      get("k") < -0.01 || (k_se != se.end() && std::isfinite(k_se->second) && get("k") + 2.0 * k_se->second < 0.0);
  if (effect == "turn_scrub" && scrub_negative)
    return fmt::format("a negative turn scrub (k = {:.3g}): scrubbing can only lose rotation, never add it", get("k"));
  if (effect == "turn_scrub" && get("k") >= 1.0)
    return fmt::format("a turn scrub of k = {:.3g}: the robot would not turn at all", get("k"));
  if (effect == "correlated_noise" && std::abs(get("rho")) > 0.95)
    return fmt::format("a wheel-noise correlation at its bound (rho = {:.3g}): the noise is not wheel noise", get("rho"));
  if (effect == "scale_error" && std::abs(get("s")) > 0.1)
    return fmt::format("both wheels {:.1f}% off their nominal diameter: a unit or configuration error, not wear",
                       100.0 * get("s"));
  if (effect == "direction_asymmetry" && std::abs(get("a")) > 0.1)
    return fmt::format("wheels {:.1f}% larger backwards than forwards: no rigid wheel does that", 100.0 * get("a"));
  if (effect == "castor_kick" && std::abs(get("kappa")) > 0.05)
    return fmt::format("a castor kick of {:.0f} mrad ({:.1f} deg) at every start: far beyond what a castor swings the "
                       "robot", 1e3 * get("kappa"), get("kappa") * 180.0 / 3.14159265358979);
  if (effect == "castor_swivel" && std::abs(get("kappa")) > 0.05)
    return fmt::format("a swivel kick of {:.0f} mrad ({:.1f} deg) after every spot turn: far beyond what a castor "
                       "swings the robot",
                       1e3 * get("kappa"), get("kappa") * 180.0 / 3.14159265358979);
  // stop_slide: a chassis coasts on, never back; d = 1/(2 mu g) > 1 s^2/m
  // is a friction coefficient under 0.05 (wet ice).
  if (effect == "stop_slide" && (get("d") < -0.01 || get("a") < -0.01))
    return fmt::format("a negative slide (d = {:.3g} s^2/m, a = {:.3g} s^2/rad): a coasting chassis moves on, never "
                       "back",
                       get("d"), get("a"));
  if (effect == "stop_slide" && (get("d") > 1.0 || get("a") > 1.0))
    return fmt::format("a slide of d = {:.3g} s^2/m, a = {:.3g} s^2/rad: a friction coefficient below 0.05",
                       get("d"), get("a"));
  if (effect == "gt_offset" && std::hypot(get("dx"), get("dy")) > 0.3)
    return fmt::format("a ground-truth marker {:.0f} mm from the axle midpoint: off the robot",
                       1e3 * std::hypot(get("dx"), get("dy")));
  if (effect == "parameter_drift" && std::abs(get("r")) * std::max(runs - 1, 1) > 0.05)
    return fmt::format("the right wheel changing by {:.1f}% over {} runs", 100.0 * get("r") * std::max(runs - 1, 1), runs);
  for (const char* k : {"sigma", "sigma_xy"})
    if (params.count(k) && get(k) > 0.05)
      return fmt::format("{} mm of noise per event ({}): larger than any slip or settling; a ground-truth glitch or a "
                         "mismatched run is more likely", fmt::format("{:.0f}", 1e3 * get(k)), k);
  if (effect == "run_time_offset" && get("tau_sd") > 1.0)
    return fmt::format("run time offsets of {:.1f} s: the recordings are not aligned at all", get("tau_sd"));
  return {};
}

std::string NullNoiseFit(const std::string& effect, const std::map<std::string, double>& params) {
  // The largest value of each parameter that still counts as zero.
  static const std::map<std::string, double> kZero = {{"sigma_xy", 1e-6}, {"sigma_theta", 1e-6}, {"sigma", 1e-6},
                                                      {"tau_sd", 1e-5},   {"rho", 1e-4}};
  static const std::map<std::string, std::vector<std::string>> kEffects = {
      {"standstill_motion", {"sigma_xy", "sigma_theta"}},
      {"motion_noise_floor", {"sigma"}},
      {"run_time_offset", {"tau_sd"}},
      {"correlated_noise", {"rho"}}};
  if (effect == "bump_outliers") {  // no bumps, or bumps of no size
    const auto r = params.find("rate"), sg = params.find("sigma");
    if (r == params.end() || sg == params.end()) return {};
    if (r->second <= 1e-6) return "fitted at rate = 0: it adds nothing, so what its fit gains is the other noise refitted beside it";
    if (sg->second <= 1e-6) return "fitted at sigma = 0: it adds nothing, so what its fit gains is the other noise refitted beside it";
    return {};
  }
  const auto it = kEffects.find(effect);
  if (it == kEffects.end()) return {};
  std::string values;
  for (const std::string& k : it->second) {
    const auto v = params.find(k);
    if (v == params.end() || !(std::abs(v->second) <= kZero.at(k))) return {};
    values += fmt::format("{}{} = 0", values.empty() ? "" : ", ", k);
  }
  return fmt::format("fitted at {}: it adds nothing, so what its fit gains is the other noise refitted beside it",
                     values);
}

}  // namespace umbmark::diag
