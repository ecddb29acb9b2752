// bump_outliers (contract): per wheel, Poisson bumps with `rate` per metre
// of travel, each adding N(0, sigma^2) m of travel.
#include <fmt/format.h>

#include <cmath>

#include "effects/effect.hpp"

namespace umbmark::effects {
namespace {

/// A run's bumps: per wheel, the travel left to the next bump (exponential
/// with mean 1 / rate), each bump N(0, sigma^2) m, from the run's stream.
class BumpRun final : public RunEffect {
 public:
  BumpRun(double rate, double sigma, RandomSource& rng) : rate_(rate), sigma_(sigma), rng_(rng) {
    to_bump_[0] = rng_.Exponential() / rate_;
    to_bump_[1] = rng_.Exponential() / rate_;
  }
  void StepTravel(const SimMotion& /*m*/, const SimStep& s, double (&travel)[2]) override {
    for (int w = 0; w < 2; ++w) {
      double left_to_roll = s.mean_abs[w];
      while (to_bump_[w] <= left_to_roll) {
        travel[w] += sigma_ * rng_.Normal();
        left_to_roll -= to_bump_[w];
        to_bump_[w] = rng_.Exponential() / rate_;
        s.bumps[w] += 1;
      }
      to_bump_[w] -= left_to_roll;
    }
  }

 private:
  double rate_, sigma_;
  RandomSource& rng_;
  double to_bump_[2];
};

class BumpOutliers final : public Effect {
 public:
  BumpOutliers()
      : Effect({.name = "bump_outliers",
                .kind = EffectKind::kBumpOutliers,
                .order = 4,
                .effect_class = EffectClass::kNoise,
                .random = true,
                .definition =
                    "per wheel, Poisson bumps with `rate` per metre of travel, each adding N(0, sigma^2) m of travel",
                .parameters = {{"rate", &Effects::bump_rate, "1/m"}, {"sigma", &Effects::bump_sigma, "m"}},
                .noise_term = NoiseTerm::kBumps,
                .sim_stream = 102}) {}

  std::unique_ptr<RunEffect> StartRun(const Effects& e, RandomSource& rng) const override {
    return std::make_unique<BumpRun>(e.bump_rate, e.bump_sigma, rng);
  }
  Params FromNoise(const NoiseValues& n) const override { return {{"rate", n.bumps_per_m}, {"sigma", std::sqrt(n.bump_var)}}; }

  // Bumps need both a rate and a size.
  bool Active(const Effects& e) const override { return e.bump_rate > 0.0 && e.bump_sigma > 0.0; }

  std::string Unphysical(const Params& p, int /*runs*/, const Params& /*se*/) const override {
    return NoisePerEventTooLarge(p, "sigma");
  }

  // No bumps, or bumps of no size.
  std::string NullFit(const Params& p) const override {
    const auto r = p.find("rate"), sg = p.find("sigma");
    if (r == p.end() || sg == p.end()) return {};
    if (r->second <= 1e-6)
      return "fitted at rate = 0: it adds nothing, so what its fit gains is the other noise refitted beside it";
    if (sg->second <= 1e-6)
      return "fitted at sigma = 0: it adds nothing, so what its fit gains is the other noise refitted beside it";
    return {};
  }

  std::string PlainProblem(const Params& p) const override {
    return fmt::format("the wheels hit bumps or slip ({:.2g} per metre, {:.1f} mm each)", Get(p, "rate"),
                       1e3 * Get(p, "sigma"));
  }

 protected:
  std::string Range(const Effects& e) const override {
    if (e.bump_rate < 0.0) return fmt::format("bump_outliers.rate = {} must be >= 0", e.bump_rate);
    if (e.bump_sigma < 0.0) return fmt::format("bump_outliers.sigma = {} must be >= 0", e.bump_sigma);
    if (e.bump_rate > 1000.0) return fmt::format("bump_outliers.rate = {} must be <= 1000 per metre", e.bump_rate);
    return {};
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(BumpOutliers)
