// direction_asymmetry (contract): a wheel turning backwards has (1 + a)
// times its forward effective diameter.
#include <cmath>

#include <fmt/format.h>

#include "effects/effect.hpp"

namespace umbmark::effects {
namespace {

class DirectionAsymmetry final : public Effect {
 public:
  DirectionAsymmetry()
      : Effect({.name = "direction_asymmetry",
                .kind = EffectKind::kDirectionAsymmetry,
                .order = 2,
                .effect_class = EffectClass::kMechanism,
                .definition = "a wheel turning backwards has (1 + a) times its forward effective diameter",
                .parameters = {{"a", &Effects::asymmetry_a, "", 0.01}},
                .mean_terms = {kTermAsym},
                .separated_by = SeparatingExperiment::kBackAndForth}) {}

  std::string Unphysical(const Params& p, int /*runs*/, const Params& /*se*/) const override {
    if (std::abs(Get(p, "a")) > 0.1)
      return fmt::format("wheels {:.1f}% larger backwards than forwards: no rigid wheel does that", 100.0 * Get(p, "a"));
    return {};
  }

  std::string ConcreteChange(const Params& p, const AdviceContext& /*c*/) const override {
    return fmt::format("Driving backward the wheels travel {:.2f}% {} per turn than forward: calibrate the backward "
                       "direction separately (or check for backlash in the gears).",
                       100.0 * std::abs(Get(p, "a")), Get(p, "a") >= 0.0 ? "more" : "less");
  }

  std::string PlainProblem(const Params& p) const override {
    return fmt::format("driving backward the wheels travel {:.2f}% {} than forward", 100.0 * std::abs(Get(p, "a")),
                       Get(p, "a") >= 0.0 ? "more" : "less");
  }

  std::pair<double, const char*> ParamUnit(std::string_view param) const override {
    if (param == "a") return {1e2, " %"};
    return {0.0, ""};
  }

  // Simulation: backward travel 1 + a times the forward.
  double BackwardFactor(const Effects& e) const override { return 1.0 + e.asymmetry_a; }

 protected:
  std::string Range(const Effects& e) const override {
    if (!(e.asymmetry_a > -0.5 && e.asymmetry_a < 0.5))
      return fmt::format("direction_asymmetry.a = {} must be in (-0.5, 0.5)", e.asymmetry_a);
    return {};
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(DirectionAsymmetry)
