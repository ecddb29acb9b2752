// diameter_ratio_error (contract): a parameter error of a model the user gives
// (`diagnose --baseline CAL.json`): the given model's wheel-diameter ratio differs from the robot's. A candidate
// of the diagnosis only, never simulated (simulate the robot with other
// parameters instead); its fit and correction live in the diagnosis's
// given-model code (baseline_given.hpp).
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
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(DiameterRatioError)
