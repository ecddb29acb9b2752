// castor_swivel (contract): at the start of a straight or arc motion that
// follows a spot turn the heading jumps kappa x the turn's sign (ccw +1, cw
// -1); after a reversal of the drive direction +-kappa with equal
// probability.
#include <cmath>

#include <fmt/format.h>

#include "effects/effect.hpp"

namespace umbmark::effects {
namespace {

// A swivel castor's kick of at most 0.5 rad (29 deg).
constexpr double kMaxSwivelKappa = 0.5;

/// A run's swivel kicks: it remembers the last spot turn's sign since the
/// last straight or arc motion (0: none) and that motion's drive sign (0:
/// none yet); a reversal draws the kick's sign from the run's stream.
class SwivelRun final : public RunEffect {
 public:
  SwivelRun(double kappa, RandomSource& rng) : kappa_(kappa), rng_(rng) {}
  void MotionStart(const SimMotion& m, Pose2& pose) override {
    if (!m.motion_start) return;
    if (m.turn) {
      last_turn_sign_ = m.sign;
      return;
    }
    if (last_turn_sign_ != 0)
      pose.theta += last_turn_sign_ * kappa_;
    else if (last_drive_sign_ != 0 && m.sign != last_drive_sign_)
      pose.theta += (rng_.Uniform() < 0.5 ? -1.0 : 1.0) * kappa_;
    last_drive_sign_ = m.sign;
    last_turn_sign_ = 0;
  }

 private:
  double kappa_;
  RandomSource& rng_;
  int last_turn_sign_ = 0, last_drive_sign_ = 0;
};

class CastorSwivel final : public Effect {
 public:
  CastorSwivel()
      : Effect({.name = "castor_swivel",
                .kind = EffectKind::kCastorSwivel,
                .order = 13,
                .effect_class = EffectClass::kMechanism,
                .at_motion_starts = true,
                .definition = "at the start of a straight or arc motion after a spot turn the heading jumps by kappa "
                              "times the turn's sign (ccw +1, cw -1); after a reversal of the drive direction by "
                              "+kappa or -kappa with equal probability",
                // As castor_kick.
                .parameters = {{"kappa", &Effects::swivel_kappa, "rad", 0.005}},
                .mean_terms = {kTermSwivel},
                .sim_stream = 108}) {}

  std::unique_ptr<RunEffect> StartRun(const Effects& e, RandomSource& rng) const override {
    return std::make_unique<SwivelRun>(e.swivel_kappa, rng);
  }

  // The range first: it catches NaN with the allowed range.
  std::string Check(const Effects& e) const override {
    if (!(std::abs(e.swivel_kappa) <= kMaxSwivelKappa))
      return fmt::format("castor_swivel.kappa = {} must be in [-{}, {}] rad", e.swivel_kappa, kMaxSwivelKappa,
                         kMaxSwivelKappa);
    return Effect::Check(e);
  }

  std::string PracticalFloor(const Params& p, const CampaignScale& c) const override {
    return HeadingJumpFloor(p, c, "kappa");
  }

  std::string Unphysical(const Params& p, int /*runs*/, const Params& /*se*/) const override {
    const double kappa = Get(p, "kappa");
    if (std::abs(kappa) > 0.05)
      return fmt::format("a swivel kick of {:.0f} mrad ({:.1f} deg) after every spot turn: far beyond what a castor "
                         "swings the robot",
                         1e3 * kappa, kappa * 180.0 / 3.14159265358979);
    return {};
  }

  std::string ConcreteChange(const Params& p, const AdviceContext& /*c*/) const override {
    return fmt::format("Swivel castor: after a spot turn the heading jumps by {:.1f} mrad (with the turn's sign) at "
                       "the next start. A castor with less trail or play, or a short straight creep after turns.",
                       1e3 * Get(p, "kappa"));
  }

  std::string PlainProblem(const Params& p) const override {
    return fmt::format("the swivel castor turns the robot by {:.1f} mrad as it starts after a spot turn",
                       1e3 * std::abs(Get(p, "kappa")));
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(CastorSwivel)
