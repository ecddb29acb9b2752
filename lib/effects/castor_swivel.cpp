// castor_swivel (contract): at the start of a straight or arc motion that
// follows a spot turn the heading jumps kappa x the turn's sign (ccw +1, cw
// -1); after a reversal of the drive direction +-kappa with equal
// probability.
// Extension (docs/diagnosis.md, "A swivel castor's first start"): a castor
// rests at a random angle when a run begins, so the run's first start, a
// straight or arc motion with no turn before it, kicks the heading by
// N(0, kappa_start^2) and slips the position by N(0, slip_start^2) along
// each robot axis, drawn per run (the castor drags the robot while it
// swings round); and the kick after a spot turn scatters around its mean:
// the turn's sign x kappa + N(0, kappa_sd^2). kappa_start = slip_start =
// kappa_sd = 0 (the default) is the contract's definition exactly (no draw
// from the stream). The diagnosis fits the three as variances
// (NoiseTerm::kFirstStart) jointly with kappa.
#include <algorithm>
#include <cmath>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "effects/effect.hpp"

namespace umbmark::effects {
namespace {

// A swivel castor's kick of at most 0.5 rad (29 deg); its first start's
// sd likewise.
constexpr double kMaxSwivelKappa = 0.5;
// A first start's kick with an sd over 0.2 rad (11 deg): the robot would
// swing by a quarter turn now and then as a run begins, far beyond what
// the castor's trail can do (the DART robots show 10-50 mrad).
constexpr double kMaxPlausibleStartSd = 0.2;
// A first start's slip of at most 0.1 m (sd); over 30 mm the castor would
// shove the robot by more than its own trail.
constexpr double kMaxSlipStart = 0.1;
constexpr double kMaxPlausibleSlip = 0.03;

/// A run's swivel kicks: it remembers the last spot turn's sign since the
/// last straight or arc motion (0: none) and that motion's drive sign (0:
/// none yet); a reversal draws the kick's sign from the run's stream.
class SwivelRun final : public RunEffect {
 public:
  SwivelRun(const Effects& e, RandomSource& rng)
      : kappa_(e.swivel_kappa),
        kappa_start_(e.swivel_kappa_start),
        slip_start_(e.swivel_slip_start),
        kappa_sd_(e.swivel_kappa_sd),
        rng_(rng) {}
  void MotionStart(const SimMotion& m, Pose2& pose) override {
    if (!m.motion_start) return;
    // The run's first start: the castor swings from where it rested.
    const bool first = !started_;
    started_ = true;
    if (first && !m.turn) FirstStart(pose);
    if (m.turn) {
      last_turn_sign_ = m.sign;
      return;
    }
    if (last_turn_sign_ != 0)
      pose.theta += last_turn_sign_ * kappa_ + (kappa_sd_ != 0.0 ? kappa_sd_ * rng_.Normal() : 0.0);
    else if (last_drive_sign_ != 0 && m.sign != last_drive_sign_)
      pose.theta += (rng_.Uniform() < 0.5 ? -1.0 : 1.0) * kappa_;
    last_drive_sign_ = m.sign;
    last_turn_sign_ = 0;
  }

 private:
  // The first start's random kick and slip (robot frame at the start).
  void FirstStart(Pose2& pose) {
    if (kappa_start_ != 0.0) pose.theta += kappa_start_ * rng_.Normal();
    if (slip_start_ == 0.0) return;
    const double along = slip_start_ * rng_.Normal(), left = slip_start_ * rng_.Normal();
    pose.x += std::cos(pose.theta) * along - std::sin(pose.theta) * left;
    pose.y += std::sin(pose.theta) * along + std::cos(pose.theta) * left;
  }

  double kappa_, kappa_start_, slip_start_, kappa_sd_;
  RandomSource& rng_;
  int last_turn_sign_ = 0, last_drive_sign_ = 0;
  bool started_ = false;
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
                              "+kappa or -kappa with equal probability; extension: the run's first start, a "
                              "straight or arc motion with no turn before it, by N(0, kappa_start^2), and its "
                              "position slips by N(0, slip_start^2) along each robot axis, drawn per run (the castor "
                              "rests at a random angle); after a spot turn the kick scatters by N(0, kappa_sd^2) "
                              "around kappa (all three 0 by default)",
                // kappa as castor_kick; kappa_start: the DART robots' 10-50
                // mrad; slip_start: their few mm.
                .parameters = {{"kappa", &Effects::swivel_kappa, "rad", 0.005},
                               {"kappa_start", &Effects::swivel_kappa_start, "rad", 0.02},
                               {"slip_start", &Effects::swivel_slip_start, "m", 0.003},
                               {"kappa_sd", &Effects::swivel_kappa_sd, "rad", 0.003}},
                .mean_terms = {kTermSwivel},
                .noise_term = NoiseTerm::kFirstStart,
                .sim_stream = 108}) {}

  std::unique_ptr<RunEffect> StartRun(const Effects& e, RandomSource& rng) const override {
    return std::make_unique<SwivelRun>(e, rng);
  }

  // The range first: it catches NaN with the allowed range.
  std::string Check(const Effects& e) const override {
    if (!(std::abs(e.swivel_kappa) <= kMaxSwivelKappa))
      return fmt::format("castor_swivel.kappa = {} must be in [-{}, {}] rad", e.swivel_kappa, kMaxSwivelKappa,
                         kMaxSwivelKappa);
    if (!(e.swivel_kappa_start >= 0.0 && e.swivel_kappa_start <= kMaxSwivelKappa))
      return fmt::format("castor_swivel.kappa_start = {} must be in [0, {}] rad", e.swivel_kappa_start,
                         kMaxSwivelKappa);
    if (!(e.swivel_kappa_sd >= 0.0 && e.swivel_kappa_sd <= kMaxSwivelKappa))
      return fmt::format("castor_swivel.kappa_sd = {} must be in [0, {}] rad", e.swivel_kappa_sd, kMaxSwivelKappa);
    if (!(e.swivel_slip_start >= 0.0 && e.swivel_slip_start <= kMaxSlipStart))
      return fmt::format("castor_swivel.slip_start = {} must be in [0, {}] m", e.swivel_slip_start, kMaxSlipStart);
    return Effect::Check(e);
  }

  // The fitted first-start variance (kappa_start is the sd).
  Params FromNoise(const NoiseValues& n) const override {
    return {{"kappa_start", std::sqrt(std::max(n.first_start_th2, 0.0))},
            {"slip_start", std::sqrt(std::max(n.first_start_xy2, 0.0))},
            {"kappa_sd", std::sqrt(std::max(n.turn_start_th2, 0.0))}};
  }

  std::pair<double, const char*> ParamUnit(std::string_view param) const override {
    if (param == "kappa_start" || param == "kappa_sd") return {1e3, " mrad"};
    if (param == "slip_start") return {1e3, " mm"};
    return {0.0, ""};
  }

  std::string PracticalFloor(const Params& p, const CampaignScale& c) const override {
    // Negligible only when its random parts are too.
    if (Get(p, "kappa_start") >= c.FloorRad() || Get(p, "kappa_sd") >= c.FloorRad() ||
        Get(p, "slip_start") >= c.FloorM())
      return {};
    return HeadingJumpFloor(p, c, "kappa");
  }

  std::string Unphysical(const Params& p, int /*runs*/, const Params& /*se*/) const override {
    const double kappa = Get(p, "kappa");
    if (std::abs(kappa) > 0.05)
      return fmt::format("a swivel kick of {:.0f} mrad ({:.1f} deg) after every spot turn: far beyond what a castor "
                         "swings the robot",
                         1e3 * kappa, kappa * 180.0 / 3.14159265358979);
    const double start = Get(p, "kappa_start");
    if (start > kMaxPlausibleStartSd)
      return fmt::format("a first-start kick of sd {:.0f} mrad ({:.1f} deg): far beyond what a castor resting at a "
                         "random angle swings the robot",
                         1e3 * start, start * 180.0 / 3.14159265358979);
    if (const double sd = Get(p, "kappa_sd"); sd > kMaxPlausibleStartSd)
      return fmt::format("a swivel kick scattering by {:.0f} mrad (sd) after spot turns: far beyond what a castor "
                         "swings the robot",
                         1e3 * sd);
    if (const double slip = Get(p, "slip_start"); slip > kMaxPlausibleSlip)
      return fmt::format("a first-start slip of sd {:.0f} mm: more than a castor's drag shoves the robot", 1e3 * slip);
    return {};
  }

  std::string ConcreteChange(const Params& p, const AdviceContext& /*c*/) const override {
    // The first start's part is stated when it is at least 0.5 mrad or 0.5
    // mm (the default practical floor's size).
    const double start = Get(p, "kappa_start"), slip = Get(p, "slip_start"), sd = Get(p, "kappa_sd");
    const bool first = start >= 5e-4 || slip >= 5e-4;
    return fmt::format("Swivel castor: after a spot turn the heading jumps by {:.1f} mrad (with the turn's sign) at "
                       "the next start{}{}. A castor with less trail or play, or a short straight creep after turns{}.",
                       1e3 * Get(p, "kappa"),
                       sd >= 5e-4 ? fmt::format(" (scattering by {:.1f} mrad sd)", 1e3 * sd) : "",
                       first ? fmt::format(", and at each run's first start, where the castor swings from the angle "
                                           "it rested at, by a random {:.1f} mrad and {:.1f} mm (sd)",
                                           1e3 * start, 1e3 * slip)
                             : "",
                       first ? " and before each run (align the castor with a short forward creep)" : "");
  }

  std::string PlainProblem(const Params& p) const override {
    return fmt::format("the swivel castor turns the robot by {:.1f} mrad as it starts after a spot turn",
                       1e3 * std::abs(Get(p, "kappa")));
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(CastorSwivel)
