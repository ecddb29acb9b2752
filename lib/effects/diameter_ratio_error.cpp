// diameter_ratio_error (contract): a parameter error of a model the user gives
// (`diagnose --baseline CAL.json`): the given model's wheel-diameter ratio differs from the robot's. A candidate
// of the diagnosis only, never simulated (simulate the robot with other
// parameters instead); its fit lives in the diagnosis' given-model code
// (baseline_given.hpp), its description and correction here.
#include <cmath>

#include <fmt/format.h>

#include "effects/effect.hpp"

namespace umbmark::effects {
namespace {

class DiameterRatioError final : public Effect {
 public:
  DiameterRatioError()
      : Effect({.name = "diameter_ratio_error",
                .kind = EffectKind::kDiameterRatioError,
                .order = 201,
                .effect_class = EffectClass::kMechanism,
                .parameter_error = true,
                .definition = "(diagnose --baseline) the given model's wheel-diameter ratio differs from the robot's",
                .parameters = {},
                .mean_terms = {kTermEd}}) {}

  // E_d is relative to the recorded ratio; the scale (mean diameter factor)
  // stays the given model's.
  Params DescribeGiven(const Params& raw, const GivenContext& g) const override {
    const double E_d = GetOr(raw, "E_d", g.E_d);
    const double rec_ratio = g.recorded.wheel_diameter_right_m / g.recorded.wheel_diameter_left_m;
    const double shown = E_d * rec_ratio;
    const double given_ratio = g.given.wheel_diameter_right_m / g.given.wheel_diameter_left_m;
    const double scale = 1.0 + g.scale;
    return {{"ratio", shown},
            {"ratio_given", given_ratio},
            {"error_ppm", 1e6 * (given_ratio / shown - 1.0)},
            {"wheel_diameter_left_m", g.recorded.wheel_diameter_left_m * scale * 2.0 / (E_d + 1.0)},
            {"wheel_diameter_right_m", g.recorded.wheel_diameter_right_m * scale * 2.0 * E_d / (E_d + 1.0)}};
  }

  Params DescribeGivenErrors(const Params& raw_se, const GivenContext& g) const override {
    const auto it = raw_se.find("E_d");
    if (it == raw_se.end()) return {};
    const double rec_ratio = g.recorded.wheel_diameter_right_m / g.recorded.wheel_diameter_left_m;
    return {{"ratio", it->second * rec_ratio}, {"error_ppm", 1e6 * it->second}};
  }

  std::vector<GivenCorrection> GivenCorrections(const Params& d, const GivenContext& g,
                                                double /*negligible*/) const override {
    const double ppm = GetOr(d, "error_ppm", 0.0);
    const std::string text = fmt::format(
        "the simulation's wheel-diameter ratio D_R/D_L is {:.0f} ppm ({:.3f} %) too {}: set wheel_diameter_left_m "
        "= {:.6f}, wheel_diameter_right_m = {:.6f} (were {:.6f}, {:.6f}; mean diameter kept)",
        std::abs(ppm), 1e-4 * std::abs(ppm), ppm > 0.0 ? "large" : "small", GetOr(d, "wheel_diameter_left_m", 0.0),
        GetOr(d, "wheel_diameter_right_m", 0.0), g.given.wheel_diameter_left_m, g.given.wheel_diameter_right_m);
    return {{"wheel_diameter_left_m", g.given.wheel_diameter_left_m, GetOr(d, "wheel_diameter_left_m", 0.0), "m",
             text},
            {"wheel_diameter_right_m", g.given.wheel_diameter_right_m, GetOr(d, "wheel_diameter_right_m", 0.0), "m",
             text}};
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(DiameterRatioError)
