// standstill_motion (contract): after every motion, while the encoders read
// still, the true pose moves by N(0, sigma_xy^2) m along each robot axis and
// N(0, sigma_theta^2) rad in heading (once per standstill; the simulator
// applies it as the standstill begins).
#include <fmt/format.h>

#include <cmath>

#include "effects/effect.hpp"

namespace umbmark::effects {
namespace {

/// A run's settling: as a standstill begins after a motion that stops
/// (not at the run's end), N(0, sigma_xy^2) along each robot axis and
/// N(0, sigma_theta^2) in heading, from the run's stream.
class SettleRun final : public RunEffect {
 public:
  SettleRun(double sigma_xy, double sigma_theta, RandomSource& rng)
      : sigma_xy_(sigma_xy), sigma_theta_(sigma_theta), rng_(rng) {}
  bool AtStop(const SimMotion& m, double& dx, double& dy, double& dtheta) override {
    if (!m.stops || !m.standstill_follows) return false;
    dx = sigma_xy_ * rng_.Normal();
    dy = sigma_xy_ * rng_.Normal();
    dtheta = sigma_theta_ * rng_.Normal();
    return true;
  }

 private:
  double sigma_xy_, sigma_theta_;
  RandomSource& rng_;
};

class StandstillMotion final : public Effect {
 public:
  StandstillMotion()
      : Effect({.name = "standstill_motion",
                .kind = EffectKind::kStandstillMotion,
                .order = 9,
                .effect_class = EffectClass::kNoise,
                .random = true,
                .definition = "after every motion, while the encoders read still, the true pose moves by N(0, "
                              "sigma_xy^2) m along each robot axis and N(0, sigma_theta^2) rad in heading, "
                              "independently per standstill",
                .parameters = {{"sigma_xy", &Effects::stand_sigma_xy, "m"},
                               {"sigma_theta", &Effects::stand_sigma_theta, "rad"}},
                .noise_term = NoiseTerm::kStandstill,
                .sim_stream = 105,
                .separated_by = SeparatingExperiment::kStandstills}) {}

  std::unique_ptr<RunEffect> StartRun(const Effects& e, RandomSource& rng) const override {
    if (!(e.stand_sigma_xy > 0.0 || e.stand_sigma_theta > 0.0)) return nullptr;
    return std::make_unique<SettleRun>(e.stand_sigma_xy, e.stand_sigma_theta, rng);
  }
  Params FromNoise(const NoiseValues& n) const override { return {{"sigma_xy", std::sqrt(n.stand_xy2)}, {"sigma_theta", std::sqrt(n.stand_th2)}}; }

  std::string Unphysical(const Params& p, int /*runs*/, const Params& /*se*/) const override {
    return NoisePerEventTooLarge(p, "sigma_xy");
  }

  std::string NullFit(const Params& p) const override {
    return FittedAtZero(p, {{"sigma_xy", 1e-6}, {"sigma_theta", 1e-6}});
  }

  std::string PlainProblem(const Params& p) const override {
    return fmt::format("the robot still moves as it comes to rest (about {:.1f} mm, {:.1f} mrad)",
                       1e3 * Get(p, "sigma_xy"), 1e3 * Get(p, "sigma_theta"));
  }

 protected:
  std::string Range(const Effects& e) const override {
    if (!(e.stand_sigma_xy >= 0.0 && e.stand_sigma_xy < 1.0))
      return fmt::format("standstill_motion.sigma_xy = {} must be in [0, 1) m", e.stand_sigma_xy);
    if (!(e.stand_sigma_theta >= 0.0 && e.stand_sigma_theta < 0.5))
      return fmt::format("standstill_motion.sigma_theta = {} must be in [0, 0.5) rad", e.stand_sigma_theta);
    return {};
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(StandstillMotion)
