// correlated_noise (contract): left and right random wheel errors have
// correlation rho.
#include <cmath>

#include <fmt/format.h>

#include "effects/effect.hpp"

namespace umbmark::effects {
namespace {

class CorrelatedNoise final : public Effect {
 public:
  CorrelatedNoise()
      : Effect({.name = "correlated_noise",
                .kind = EffectKind::kCorrelatedNoise,
                .order = 5,
                .effect_class = EffectClass::kNoise,
                .random = true,
                .definition = "left and right random wheel errors have correlation rho",
                .parameters = {{"rho", &Effects::noise_rho, ""}},
                .noise_term = NoiseTerm::kCorrelated}) {}
  Params FromNoise(const NoiseValues& n) const override { return {{"rho", n.rho}}; }

  std::string Unphysical(const Params& p, int /*runs*/, const Params& /*se*/) const override {
    if (std::abs(Get(p, "rho")) > 0.95)
      return fmt::format("a wheel-noise correlation at its bound (rho = {:.3g}): the noise is not wheel noise",
                         Get(p, "rho"));
    return {};
  }

  std::string NullFit(const Params& p) const override { return FittedAtZero(p, {{"rho", 1e-4}}); }

  std::string PlainProblem(const Params& p) const override {
    return fmt::format("the two wheels' errors are correlated (rho = {:.2f})", Get(p, "rho"));
  }

  // Simulation: the wheels' noise correlated by rho.
  double WheelNoiseCorrelation(const Effects& e) const override { return e.noise_rho; }

 protected:
  std::string Range(const Effects& e) const override {
    if (!(std::abs(e.noise_rho) <= 1.0)) return fmt::format("correlated_noise.rho = {} must be in [-1, 1]", e.noise_rho);
    return {};
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(CorrelatedNoise)
