// parameter_drift (contract): in run i (0-based, campaign order) the true
// right wheel diameter is (1 + r i) times run 0's.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "effects/effect.hpp"

namespace umbmark::effects {
namespace {

class ParameterDrift final : public Effect {
 public:
  ParameterDrift()
      : Effect({.name = "parameter_drift",
                .kind = EffectKind::kParameterDrift,
                .order = 6,
                .effect_class = EffectClass::kMechanism,
                .definition = "in run i of the campaign the true right wheel diameter is (1 + r i) times run 0's",
                .parameters = {{"r", &Effects::drift_r, "1/run", 1e-4}},
                .mean_terms = {kTermDrift}}) {}

  std::string Unphysical(const Params& p, int runs, const Params& /*se*/) const override {
    const double r = Get(p, "r");
    if (std::abs(r) * std::max(runs - 1, 1) > 0.05)
      return fmt::format("the right wheel changing by {:.1f}% over {} runs", 100.0 * r * std::max(runs - 1, 1), runs);
    return {};
  }

  std::string ConcreteChange(const Params& p, const AdviceContext& c) const override {
    const double r = Get(p, "r");
    return fmt::format("The right wheel's diameter drifts by {:.3g}% per run ({:.2g}% over the {} runs): tyre wear, "
                       "pressure or temperature. Re-calibrate between sessions, or let the wheels warm up first.",
                       100.0 * r, 100.0 * r * std::max(0, c.runs - 1), c.runs);
  }

  void TrueWheels(const Effects& e, int run_index, double& /*left*/, double& right) const override {
    right *= 1.0 + e.drift_r * static_cast<double>(run_index);
  }

  std::string CheckCampaign(const Effects& e, int runs) const override {
    if (!(1.0 + e.drift_r * static_cast<double>(std::max(0, runs - 1)) > 0.0))
      return fmt::format("parameter_drift.r = {} makes the right wheel diameter <= 0 by run {}", e.drift_r, runs - 1);
    return {};
  }

  std::string PlainProblem(const Params& p) const override {
    return fmt::format("the right wheel's diameter changes by {:.3g}% from run to run", 100.0 * Get(p, "r"));
  }

 protected:
  std::string Range(const Effects& e) const override {
    if (!(std::abs(e.drift_r) < 0.1)) return fmt::format("parameter_drift.r = {} must be in (-0.1, 0.1)", e.drift_r);
    return {};
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(ParameterDrift)
