// wheel_noise_error (contract): a parameter error of a model the user gives
// (`diagnose --baseline CAL.json`): the given wheel noise k_L, k_R differs from the robot's. A candidate
// of the diagnosis only, never simulated (simulate the robot with other
// parameters instead); its fit and correction live in the diagnosis's
// given-model code (baseline_given.hpp).
#include <cmath>

#include "effects/effect.hpp"

namespace umbmark::effects {
namespace {

class WheelNoiseError final : public Effect {
 public:
  WheelNoiseError()
      : Effect({.name = "wheel_noise_error",
                .kind = EffectKind::kWheelNoiseError,
                .order = 202,
                .effect_class = EffectClass::kNoise,
                .random = true,
                .parameter_error = true,
                .definition = "(diagnose --baseline) the given wheel noise k_L, k_R differs from the robot's",
                .parameters = {},
                .noise_term = NoiseTerm::kWheelNoise}) {}
  Params FromNoise(const NoiseValues& n) const override { return {{"k_L", std::sqrt(n.kL2)}, {"k_R", std::sqrt(n.kR2)}}; }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(WheelNoiseError)
