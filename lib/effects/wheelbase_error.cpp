// wheelbase_error (contract): a parameter error of a model the user gives
// (`diagnose --baseline CAL.json`): the given model's wheelbase differs from the robot's. A candidate
// of the diagnosis only, never simulated (simulate the robot with other
// parameters instead); its fit and correction live in the diagnosis's
// given-model code (baseline_given.hpp).
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
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(WheelbaseError)
