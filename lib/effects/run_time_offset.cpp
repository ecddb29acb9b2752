// run_time_offset (contract): run i's ground truth stamped t shows the true
// pose at t - tau_i, tau_i ~ N(0, tau_sd^2) per run.
#include <cmath>

#include <fmt/format.h>

#include "effects/effect.hpp"

namespace umbmark::effects {
namespace {

class RunTimeOffset final : public Effect {
 public:
  RunTimeOffset()
      : Effect({.name = "run_time_offset",
                .kind = EffectKind::kRunTimeOffset,
                .order = 11,
                .effect_class = EffectClass::kMeasurement,
                .random = true,
                .definition =
                    "in run i the ground truth stamped t shows the true pose at t - tau_i, tau_i ~ N(0, tau_sd^2) per run",
                .parameters = {{"tau_sd", &Effects::run_tau_sd, "s"}},
                .noise_term = NoiseTerm::kRunTime,
                .spread_of = EffectKind::kTimeOffset}) {}
  Params FromNoise(const NoiseValues& n) const override { return {{"tau_sd", std::sqrt(n.run_tau2)}}; }

  // As time_offset, with the spread of the runs' clocks.
  std::string PracticalFloor(const Params& p, const CampaignScale& c) const override {
    const double sd = Size(p, "tau_sd");
    if (!(c.negligible > 0.0) || !(sd * c.speed_mps < c.FloorM() && sd * c.turn_rate_radps < c.FloorRad())) return {};
    return fmt::format("per-run clock offsets of {:.2f} ms ({:.2f} mm at the campaign's {:.2f} m/s, {:.2f} mrad at "
                       "{:.2f} rad/s; below {:.2g} mm and {:.2g} mrad)",
                       1e3 * sd, 1e3 * sd * c.speed_mps, c.speed_mps, 1e3 * sd * c.turn_rate_radps, c.turn_rate_radps,
                       1e3 * c.FloorM(), 1e3 * c.FloorRad());
  }

  std::string Unphysical(const Params& p, int /*runs*/, const Params& /*se*/) const override {
    if (Get(p, "tau_sd") > 1.0)
      return fmt::format("run time offsets of {:.1f} s: the recordings are not aligned at all", Get(p, "tau_sd"));
    return {};
  }

  std::string NullFit(const Params& p) const override { return FittedAtZero(p, {{"tau_sd", 1e-5}}); }

  std::string ConcreteChange(const Params& p, const AdviceContext& /*c*/) const override {
    return fmt::format(
        "Clock per run: each run's ground truth is offset from its encoders by a different amount (sd {:.0f} ms "
        "over the runs). Synchronise the clocks at the start of every recording (e.g. align on the first motion).",
        1e3 * Get(p, "tau_sd"));
  }

  // This run's tau_i ~ N(0, tau_sd^2), one draw per run.
  double GroundTruthDelay(const Effects& e, double (*draw)(void*), void* state) const override {
    return e.run_tau_sd > 0.0 ? e.run_tau_sd * draw(state) : 0.0;
  }

  std::string PlainProblem(const Params& p) const override {
    return fmt::format("each recording's ground-truth clock is offset differently (by about {:.0f} ms)",
                       1e3 * Get(p, "tau_sd"));
  }

 protected:
  std::string Range(const Effects& e) const override {
    if (!(e.run_tau_sd >= 0.0 && e.run_tau_sd < 10.0))
      return fmt::format("run_time_offset.tau_sd = {} must be in [0, 10) s", e.run_tau_sd);
    return {};
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(RunTimeOffset)
