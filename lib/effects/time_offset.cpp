// time_offset (contract): a ground-truth sample stamped t shows the true
// pose at t - tau.
#include <cmath>

#include <fmt/format.h>

#include "effects/effect.hpp"

namespace umbmark::effects {
namespace {

class TimeOffset final : public Effect {
 public:
  TimeOffset()
      : Effect({.name = "time_offset",
                .kind = EffectKind::kTimeOffset,
                .order = 8,
                .effect_class = EffectClass::kMeasurement,
                .definition = "a ground-truth sample stamped t shows the true pose at t - tau",
                .parameters = {{"tau", &Effects::time_tau, "s", 0.02}},
                .mean_terms = {kTermTau}}) {}

  // A clock offset moves the pose by tau v and the heading by tau w: below
  // both floors at the campaign's typical speed and turn rate.
  std::string PracticalFloor(const Params& p, const CampaignScale& c) const override {
    const double tau = Size(p, "tau");
    if (!(c.negligible > 0.0) || !(tau * c.speed_mps < c.FloorM() && tau * c.turn_rate_radps < c.FloorRad())) return {};
    return fmt::format("a clock offset of {:.2f} ms ({:.2f} mm at the campaign's {:.2f} m/s, {:.2f} mrad at {:.2f} "
                       "rad/s; below {:.2g} mm and {:.2g} mrad)",
                       1e3 * tau, 1e3 * tau * c.speed_mps, c.speed_mps, 1e3 * tau * c.turn_rate_radps,
                       c.turn_rate_radps, 1e3 * c.FloorM(), 1e3 * c.FloorRad());
  }

  std::string ConcreteChange(const Params& p, const AdviceContext& /*c*/) const override {
    const double tau = Get(p, "tau");
    return fmt::format(
        "Clock: the ground truth {} the encoders by {:.1f} ms (a sample stamped t shows the pose at t {} {:.1f} ms). "
        "Shift the ground-truth timestamps by {:+.1f} ms (or the encoders' by {:+.1f} ms), or synchronise the two "
        "clocks.",
        tau >= 0.0 ? "lags" : "leads", 1e3 * std::abs(tau), tau >= 0.0 ? "-" : "+", 1e3 * std::abs(tau), -1e3 * tau,
        1e3 * tau);
  }

  double GroundTruthDelay(const Effects& e, double (*/*draw*/)(void*), void* /*state*/) const override {
    return e.time_tau;
  }

  std::string PlainProblem(const Params& p) const override {
    return fmt::format("the ground truth's clock {} the encoders' by {:.0f} ms", Get(p, "tau") >= 0.0 ? "lags" : "leads",
                       1e3 * std::abs(Get(p, "tau")));
  }

 protected:
  std::string Range(const Effects& e) const override {
    if (!(std::abs(e.time_tau) < 10.0)) return fmt::format("time_offset.tau = {} must be in (-10, 10) s", e.time_tau);
    return {};
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(TimeOffset)
