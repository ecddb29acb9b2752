// stop_slide (contract): at every stop (a standstill follows) after a
// straight or arc motion at speed v the chassis coasts on by d v^2 m along
// its last direction of travel; after a spot turn at rate w it turns on by
// a w^2 rad. Beyond the contract its shape (arc, back; values.hpp).
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "effects/effect.hpp"
#include "kinematics/diff_drive.hpp"

namespace umbmark::effects {
namespace {

// d = 1/(2 mu g) <= 1 s^2/m is a friction coefficient of at least 0.05 (ice
// is about 0.05-0.1); a the same for the turn. Its shape (diagnosis.md, "A
// slide's shape"): arc 0-4 (2 is two locked wheels sliding forward), a
// backward coast 0.1-5 times the forward.
constexpr double kMaxSlideD = 1.0;
constexpr double kMaxSlideA = 1.0;
constexpr double kMaxSlideArc = 4.0;
constexpr double kMinSlideBack = -0.9, kMaxSlideBack = 4.0;

/// How far a coast at initial rate `rate` (signed speed or turn rate) with
/// coefficient k (d or a) has gone tau seconds after the wheels stopped:
/// uniform deceleration 1 / (2 |k|) until it rests after 2 |k| |rate|,
/// covering k rate |rate| in all (a negative k, which a fit may try, coasts
/// backwards: the slide stays smooth in k through 0).
double CoastProgress(double rate, double k, double tau) {
  if (k == 0.0 || !(tau > 0.0) || rate == 0.0) return 0.0;
  const double v = std::abs(rate), kk = std::abs(k), t = std::min(tau, 2.0 * kk * v);
  return (k > 0.0 ? 1.0 : -1.0) * (rate > 0.0 ? 1.0 : -1.0) * (v * t - t * t / (4.0 * kk));
}

class StopSlide final : public Effect {
 public:
  StopSlide()
      : Effect({.name = "stop_slide",
                .kind = EffectKind::kStopSlide,
                .order = 12,
                .effect_class = EffectClass::kMechanism,
                .at_motion_stops = true,
                .definition = "at every stop after a straight or arc motion at speed v the chassis coasts on along "
                              "its last direction of travel by d v^2 m while the encoders read still; after a spot "
                              "turn at rate w it turns on by a w^2 rad",
                // Typical: 8 mm after a leg at 0.35 m/s (d = 0.065 s^2/m, a
                // friction coefficient of 0.8), 10 mrad after a spot turn at
                // 1 rad/s; a coast along the arc (1), a backward coast 30 %
                // longer.
                .parameters = {{"d", &Effects::slide_d, "s^2/m", 0.065},
                               {"a", &Effects::slide_a, "s^2/rad", 0.01},
                               {"arc", &Effects::slide_arc, "", 1.0},
                               {"back", &Effects::slide_back, "", 0.3}},
                .mean_terms = {kTermSlideD, kTermSlideA, kTermSlideArc, kTermSlideBack}}) {}

  // The ranges first: they catch NaN with the allowed range.
  std::string Check(const Effects& e) const override {
    if (!(e.slide_d >= 0.0 && e.slide_d <= kMaxSlideD))
      return fmt::format("stop_slide.d = {} must be in [0, {}] s^2/m (d = 1/(2 mu g): a friction coefficient mu of "
                         "at least 0.05)",
                         e.slide_d, kMaxSlideD);
    if (!(e.slide_a >= 0.0 && e.slide_a <= kMaxSlideA))
      return fmt::format("stop_slide.a = {} must be in [0, {}] s^2/rad", e.slide_a, kMaxSlideA);
    if (!(e.slide_arc >= 0.0 && e.slide_arc <= kMaxSlideArc))
      return fmt::format("stop_slide.arc = {} must be in [0, {}] (2: the heading keeps turning at the arc's rate "
                         "through the coast)",
                         e.slide_arc, kMaxSlideArc);
    if (!(e.slide_back >= kMinSlideBack && e.slide_back <= kMaxSlideBack))
      return fmt::format("stop_slide.back = {} must be in [{}, {}] (a backward coast (1 + back) times as long)",
                         e.slide_back, kMinSlideBack, kMaxSlideBack);
    return Effect::Check(e);
  }

  // A chassis coasts on, never back; d = 1/(2 mu g) > 1 s^2/m is a
  // friction coefficient under 0.05 (wet ice).
  std::string Unphysical(const Params& p, int /*runs*/, const Params& /*se*/) const override {
    const double d = Get(p, "d"), a = Get(p, "a");
    if (d < -0.01 || a < -0.01)
      return fmt::format("a negative slide (d = {:.3g} s^2/m, a = {:.3g} s^2/rad): a coasting chassis moves on, never "
                         "back",
                         d, a);
    if (d > 1.0 || a > 1.0)
      return fmt::format("a slide of d = {:.3g} s^2/m, a = {:.3g} s^2/rad: a friction coefficient below 0.05", d, a);
    return {};
  }

  std::string ConcreteChange(const Params& p, const AdviceContext& /*c*/) const override {
    return fmt::format("Stops: the chassis slides on after the wheels stop (d = {:.3g} s^2/m: {:.1f} mm at 0.5 m/s). "
                       "Ramp the speed down before stops, or add grip.",
                       Get(p, "d"), 1e3 * Get(p, "d") * 0.25);
  }

  std::string PlainProblem(const Params& p) const override {
    return fmt::format("the robot slides on after its wheels stop (d = {:.3g} s^2/m)", Get(p, "d"));
  }

  // Simulation: the coast at the speed the motion ended with (backward
  // (1 + back) times as long; after an arc it turns on by arc w/v per metre).
  bool StopCoast(const Effects& e, bool turn, double rate_l, double rate_r, double b, SimCoast& c) const override {
    if (e.slide_d == 0.0 && e.slide_a == 0.0) return false;
    c.rate = turn ? (rate_r - rate_l) / b : 0.5 * (rate_l + rate_r);
    c.k = turn ? e.slide_a : e.slide_d * (c.rate < 0.0 ? 1.0 + e.slide_back : 1.0);
    if (!turn && c.rate != 0.0) c.curvature = e.slide_arc * (rate_r - rate_l) / b / c.rate;
    return true;
  }

  // Model prediction (v: d, a, arc, back): the coast between tau0 and tau1
  // seconds after the wheels stopped, at the true speed the motion ended
  // with (along the heading, or turning in the turn's sense). After an arc
  // the heading turns on by arc w/v times the distance coasted: 1, the
  // coast keeps the arc's curvature; 2, the heading keeps turning at the
  // arc's rate w through the whole coast (2 d v long) while the speed runs
  // down -- a rigid body on two locked wheels whose contacts both slide
  // forward (v > w b / 2), so that their friction forces cancel in torque
  // (DART: 2.1-2.6). A backward coast is (1 + back) times d v^2.
  bool PredictsStop(const double* v) const override { return v[0] != 0.0 || v[1] != 0.0; }
  Pose2 PredictStop(const double* v, const StopMotion& m, Pose2 q, double tau0, double tau1) const override {
    const double slide_d = v[0], slide_a = v[1], slide_arc = v[2], slide_back = v[3];
    if (m.turn) {
      const double w = (m.vr - m.vl) / m.wheelbase;
      q.theta += CoastProgress(w, slide_a, tau1) - CoastProgress(w, slide_a, tau0);
      return q;
    }
    const double speed = 0.5 * (m.vl + m.vr);
    const double d = speed < 0.0 ? slide_d * (1.0 + slide_back) : slide_d;
    const double along = CoastProgress(speed, d, tau1) - CoastProgress(speed, d, tau0);
    const double turn =
        slide_arc != 0.0 && std::abs(speed) > 1e-9 ? slide_arc * (m.vr - m.vl) / m.wheelbase / speed * along : 0.0;
    // Along the curve the coast follows (constant curvature): its chord.
    const double h = 0.5 * turn, chord = along * Sinc(h);
    return {q.x + chord * std::cos(q.theta + h), q.y + chord * std::sin(q.theta + h), q.theta + turn};
  }

  // d [s^2/m] and a [s^2/rad] in their own units; the shape (arc, back) is a
  // pure number.
  std::pair<double, const char*> ParamUnit(std::string_view param) const override {
    if (param == "arc" || param == "back") return {1.0, ""};
    return {1.0, param == "a" ? " s^2/rad" : " s^2/m"};
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(StopSlide)
