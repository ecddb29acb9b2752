// castor_kick (contract): at every start from standstill (not a spot turn)
// the true heading jumps by +kappa (forward) or -kappa (backward).
#include <cmath>

#include <fmt/format.h>

#include "effects/effect.hpp"

namespace umbmark::effects {
namespace {

/// A run's kicks: +kappa at a forward start from standstill, -kappa at a
/// backward one (spot turns excluded).
class KickRun final : public RunEffect {
 public:
  explicit KickRun(double kappa) : kappa_(kappa) {}
  void MotionStart(const SimMotion& m, Pose2& pose) override {
    if (m.from_standstill && !m.turn) pose.theta += (m.left_m + m.right_m >= 0.0 ? 1.0 : -1.0) * kappa_;
  }

 private:
  double kappa_;
};

class CastorKick final : public Effect {
 public:
  CastorKick()
      : Effect({.name = "castor_kick",
                .kind = EffectKind::kCastorKick,
                .order = 3,
                .effect_class = EffectClass::kMechanism,
                .at_motion_starts = true,
                .definition = "at every start from standstill the true heading jumps by kappa (forward) or -kappa "
                              "(backward); spot turns excluded",
                .parameters = {{"kappa", &Effects::castor_kappa, "rad", 0.005}},
                .mean_terms = {kTermKappa},
                .separated_by = SeparatingExperiment::kBackAndForth,
                .separated_rank = 2}) {}

  std::unique_ptr<RunEffect> StartRun(const Effects& e, RandomSource& /*rng*/) const override {
    return std::make_unique<KickRun>(e.castor_kappa);
  }

  // A heading kick is a pose size already: below the heading floor.
  std::string PracticalFloor(const Params& p, const CampaignScale& c) const override {
    return HeadingJumpFloor(p, c, "kappa");
  }

  std::string Unphysical(const Params& p, int /*runs*/, const Params& /*se*/) const override {
    const double kappa = Get(p, "kappa");
    if (std::abs(kappa) > 0.05)
      return fmt::format("a castor kick of {:.0f} mrad ({:.1f} deg) at every start: far beyond what a castor swings "
                         "the robot",
                         1e3 * kappa, kappa * 180.0 / 3.14159265358979);
    return {};
  }

  std::string ConcreteChange(const Params& p, const AdviceContext& /*c*/) const override {
    return fmt::format("Castor: the heading jumps by {:.1f} mrad at every start from standstill (sign with the drive "
                       "direction). Check the castor's swivel and play, or start more gently.",
                       1e3 * Get(p, "kappa"));
  }

  std::string PlainProblem(const Params& p) const override {
    return fmt::format("the castor turns the robot by {:.1f} mrad at every start", 1e3 * std::abs(Get(p, "kappa")));
  }

 protected:
  std::string Range(const Effects& e) const override {
    if (!(std::abs(e.castor_kappa) < 0.5))
      return fmt::format("castor_kick.kappa = {} must be in (-0.5, 0.5) rad", e.castor_kappa);
    return {};
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(CastorKick)
