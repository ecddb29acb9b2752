// wheelbase_error (contract): a parameter error of a model the user gives
// (`diagnose --baseline CAL.json`): the given model's wheelbase differs from the robot's. A candidate
// of the diagnosis only, never simulated (simulate the robot with other
// parameters instead); its fit lives in the diagnosis' given-model code
// (baseline_given.hpp), its description and correction here.
#include <cmath>

#include <fmt/format.h>

#include "effects/effect.hpp"

namespace umbmark::effects {
namespace {

class WheelbaseError final : public Effect {
 public:
  WheelbaseError()
      : Effect({.name = "wheelbase_error",
                .kind = EffectKind::kWheelbaseError,
                .order = 200,
                .effect_class = EffectClass::kMechanism,
                .parameter_error = true,
                .definition = "(diagnose --baseline) the given model's wheelbase differs from the robot's",
                .parameters = {},
                .mean_terms = {kTermEb}}) {}

  // The wheelbase the runs show (E_b of the recorded one) against the given.
  Params DescribeGiven(const Params& raw, const GivenContext& g) const override {
    const double shown = GetOr(raw, "E_b", g.E_b) * g.recorded.wheelbase_m;
    const double err = g.given.wheelbase_m - shown;
    return {{"wheelbase_m", shown},
            {"wheelbase_given_m", g.given.wheelbase_m},
            {"error_mm", 1e3 * err},
            {"relative_error", err / shown}};
  }

  Params DescribeGivenErrors(const Params& raw_se, const GivenContext& g) const override {
    const auto it = raw_se.find("E_b");
    if (it == raw_se.end()) return {};
    return {{"wheelbase_m", it->second * g.recorded.wheelbase_m},
            {"error_mm", 1e3 * it->second * g.recorded.wheelbase_m}};
  }

  std::vector<GivenCorrection> GivenCorrections(const Params& d, const GivenContext& g,
                                                double /*negligible*/) const override {
    const double err = GetOr(d, "error_mm", 0.0);
    return {{"wheelbase_m", g.given.wheelbase_m, GetOr(d, "wheelbase_m", 0.0), "m",
             fmt::format("the simulation's wheelbase is {:.2f} mm ({:.2f} %) too {}: set wheelbase_m = {:.5f} "
                         "(was {:.5f})",
                         std::abs(err), 100.0 * std::abs(GetOr(d, "relative_error", 0.0)),
                         err > 0.0 ? "long" : "short", GetOr(d, "wheelbase_m", 0.0), g.given.wheelbase_m)}};
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(WheelbaseError)
