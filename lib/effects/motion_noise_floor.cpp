// motion_noise_floor (contract): every motion between two standstills adds
// N(0, sigma^2) m to each wheel's true travel, whatever its length (the
// simulator: half the variance as the motion starts, half as it stops).
#include <fmt/format.h>

#include <cmath>

#include "effects/effect.hpp"

namespace umbmark::effects {
namespace {

/// A run's start and stop slip: half the variance in a motion's first step
/// when it starts from a standstill, half in its last when it stops before
/// one, from the run's stream.
class SlipRun final : public RunEffect {
 public:
  SlipRun(double sigma, RandomSource& rng) : sigma_(sigma), rng_(rng) {}
  void StepTravel(const SimMotion& m, const SimStep& s, double (&travel)[2]) override {
    const bool start_slip = m.starts && s.first, stop_slip = m.stops && s.last;
    for (int w = 0; w < 2; ++w) {
      if (start_slip) travel[w] += sigma_ * std::sqrt(0.5) * rng_.Normal();
      if (stop_slip) travel[w] += sigma_ * std::sqrt(0.5) * rng_.Normal();
    }
  }

 private:
  double sigma_;
  RandomSource& rng_;
};

class MotionNoiseFloor final : public Effect {
 public:
  MotionNoiseFloor()
      : Effect({.name = "motion_noise_floor",
                .kind = EffectKind::kMotionNoiseFloor,
                .order = 10,
                .effect_class = EffectClass::kNoise,
                .random = true,
                .definition = "every motion between two standstills adds N(0, sigma^2) m to each wheel's true travel, "
                              "independently of its length",
                .parameters = {{"sigma", &Effects::floor_sigma, "m"}},
                .noise_term = NoiseTerm::kMotionFloor,
                .sim_stream = 106}) {}

  std::unique_ptr<RunEffect> StartRun(const Effects& e, RandomSource& rng) const override {
    if (!(e.floor_sigma > 0.0)) return nullptr;
    return std::make_unique<SlipRun>(e.floor_sigma, rng);
  }
  Params FromNoise(const NoiseValues& n) const override { return {{"sigma", std::sqrt(n.floor_s2)}}; }

  std::string Unphysical(const Params& p, int /*runs*/, const Params& /*se*/) const override {
    return NoisePerEventTooLarge(p, "sigma");
  }

  std::string NullFit(const Params& p) const override { return FittedAtZero(p, {{"sigma", 1e-6}}); }

  std::string PlainProblem(const Params& p) const override {
    return fmt::format("every start and stop adds about {:.2f} mm of wheel travel error", 1e3 * Get(p, "sigma"));
  }

 protected:
  std::string Range(const Effects& e) const override {
    if (!(e.floor_sigma >= 0.0 && e.floor_sigma < 1.0))
      return fmt::format("motion_noise_floor.sigma = {} must be in [0, 1) m", e.floor_sigma);
    return {};
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(MotionNoiseFloor)
