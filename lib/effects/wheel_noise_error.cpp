// wheel_noise_error (contract): a parameter error of a model the user gives
// (`diagnose --baseline CAL.json`): the given wheel noise k_L, k_R differs from the robot's. A candidate
// of the diagnosis only, never simulated (simulate the robot with other
// parameters instead); its fit lives in the diagnosis' given-model code
// (baseline_given.hpp), its description and correction here.
#include <cmath>

#include <fmt/format.h>

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

  Params DescribeGiven(const Params& raw, const GivenContext& g) const override {
    const double kL = GetOr(raw, "k_L", g.k_L), kR = GetOr(raw, "k_R", g.k_R);
    auto ratio = [](double fit, double giv) { return giv > 0.0 ? fit / giv : 0.0; };
    return {{"k_L", kL},
            {"k_R", kR},
            {"k_L_given", g.k_L},
            {"k_R_given", g.k_R},
            {"ratio_L", ratio(kL, g.k_L)},
            {"ratio_R", ratio(kR, g.k_R)}};
  }

  // A wheel whose k is within the practical threshold of the given one
  // (|k_fit / k_given - 1| < negligible) is consistent: only the other
  // wheel's k is to change.
  std::vector<GivenCorrection> GivenCorrections(const Params& d, const GivenContext& g,
                                                double negligible) const override {
    struct Wheel {
      const char* side;
      const char* key;
      double given, fit, ratio;
    };
    const Wheel wheels[2] = {{"left", "k_L", g.k_L, GetOr(d, "k_L", 0.0), GetOr(d, "ratio_L", 0.0)},
                             {"right", "k_R", g.k_R, GetOr(d, "k_R", 0.0), GetOr(d, "ratio_R", 0.0)}};
    // A given k of 0 has no ratio (DescribeGiven gives 0): any fitted noise
    // is off.
    auto off = [&](const Wheel& w) { return w.given <= 0.0 || !(std::abs(w.ratio - 1.0) < negligible); };
    auto factor = [](const Wheel& w) {
      return w.given > 0.0 ? fmt::format("off by x{:.2f}", w.ratio) : std::string("0, but the runs show noise");
    };
    std::string text;
    if (off(wheels[0]) && off(wheels[1])) {
      text = fmt::format(
          "the simulation's wheel noise is {} (left) and {} (right): set k_L = {:.3g}, k_R = {:.3g} m^1/2 (were "
          "{:.3g}, {:.3g})",
          factor(wheels[0]), factor(wheels[1]), wheels[0].fit, wheels[1].fit, g.k_L, g.k_R);
    } else {
      const Wheel& w = off(wheels[0]) ? wheels[0] : wheels[1];
      const Wheel& ok = off(wheels[0]) ? wheels[1] : wheels[0];
      text = fmt::format(
          "the simulation's {} wheel noise is {}: set {} = {:.3g} m^1/2 (was {:.3g}); {} = {:.3g} m^1/2 is "
          "consistent with the runs (fitted x{:.2f}, within the negligible {:.0f} %): keep it",
          w.side, factor(w), w.key, w.fit, w.given, ok.key, ok.given, ok.ratio, 100.0 * negligible);
    }
    std::vector<GivenCorrection> out;
    for (const Wheel& w : wheels)
      if (off(w)) out.push_back({w.key, w.given, w.fit, "m^1/2", text});
    return out;
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(WheelNoiseError)
