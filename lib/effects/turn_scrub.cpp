// turn_scrub (contract): in on-the-spot turns the true heading change is
// (1 - k) times what the true wheel travel implies.
#include <cmath>

#include <fmt/format.h>

#include "effects/effect.hpp"

namespace umbmark::effects {
namespace {

class TurnScrub final : public Effect {
 public:
  TurnScrub()
      : Effect({.name = "turn_scrub",
                .kind = EffectKind::kTurnScrub,
                .order = 1,
                .effect_class = EffectClass::kMechanism,
                .definition =
                    "in on-the-spot turns the true heading change is (1 - k) times what the true wheel travel implies",
                .parameters = {{"k", &Effects::scrub_k, "", 0.03}},
                .mean_terms = {kTermScrub},
                .separated_by = SeparatingExperiment::kTurnsWhileDriving}) {}

  // Every rotation on the spot: a scrub is a wheelbase there. (Not when a
  // weakly identifiable scrub is told apart on its own held-out evidence:
  // the spot turns' small forward motion, E_d far from 1.)
  std::string DesignNote(const DesignFacts& f) const override {
    if (f.spot_turns == 0 || f.arcs > 0 || f.separable) return {};
    return fmt::format(
        "turn_scrub is indistinguishable from the fitted wheelbase on this design: every rotation is a spot turn, "
        "where a scrub k (heading x (1 - k)) is exactly a wheelbase of b E_b / (1 - k); the baseline's E_b = {:.5f} "
        "holds any scrub, so spot turns are predicted right but arcs would not be. To tell a scrub from a wheelbase "
        "error, add a free experiment that turns while driving (e.g. 4 figure-eight runs of about 1 m radius)",
        f.E_b);
  }

  // Negative below -0.01, or below 0 by more than 2 standard errors.
  std::string Unphysical(const Params& p, int /*runs*/, const Params& se) const override {
    const double k = Get(p, "k");
    const auto k_se = se.find("k");
    const bool negative = k < -0.01 || (k_se != se.end() && std::isfinite(k_se->second) && k + 2.0 * k_se->second < 0.0);
    if (negative)
      return fmt::format("a negative turn scrub (k = {:.3g}): scrubbing can only lose rotation, never add it", k);
    if (k >= 1.0) return fmt::format("a turn scrub of k = {:.3g}: the robot would not turn at all", k);
    return {};
  }

  std::string ConcreteChange(const Params& p, const AdviceContext& c) const override {
    const double k = Get(p, "k");
    return fmt::format(
        "Spot turns turn {:.1f}% less than the wheels say (k = {:.4f}): the wheels scrub. For spot turns the "
        "effective wheelbase is {:.5f} m (wheelbase / (1 - k)); model it as turn_scrub in the simulation, or "
        "turn while driving.",
        100.0 * k, k, c.E_b * c.robot.wheelbase_m / (1.0 - k));
  }

  std::string PlainProblem(const Params& p) const override {
    return fmt::format("spot turns turn {:.1f}% less than the wheels say (the wheels scrub)", 100.0 * Get(p, "k"));
  }

  // Simulation: a spot turn turns 1 - k times as far as its wheels say.
  double TurnHeadingFactor(const Effects& e) const override { return 1.0 - e.scrub_k; }

 protected:
  std::string Range(const Effects& e) const override {
    if (!(e.scrub_k > -0.5 && e.scrub_k < 0.5)) return fmt::format("turn_scrub.k = {} must be in (-0.5, 0.5)", e.scrub_k);
    return {};
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(TurnScrub)
