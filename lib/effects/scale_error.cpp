// scale_error (contract): both true wheel diameters are (1 + s) times the
// model's.
#include <cmath>

#include <fmt/format.h>

#include "effects/effect.hpp"

namespace umbmark::effects {
namespace {

class ScaleError final : public Effect {
 public:
  ScaleError()
      : Effect({.name = "scale_error",
                .kind = EffectKind::kScaleError,
                .order = 0,
                .effect_class = EffectClass::kMechanism,
                .definition = "both true wheel diameters are (1 + s) times the model's",
                .parameters = {{"s", &Effects::scale_s, "", 0.01}},
                .mean_terms = {kTermScale},
                .separated_by = SeparatingExperiment::kBackAndForth,
                .separated_rank = 1}) {}

  // Negligible when the travel error over one of the campaign's legs is
  // under the position floor (0.3 mm at the default negligible).
  std::string PracticalFloor(const Params& p, const CampaignScale& c) const override {
    if (!(c.negligible > 0.0)) return {};
    const double s = Size(p, "s"), mm = 1e3 * s * c.motion_length_m;
    if (!(s * c.motion_length_m < c.FloorM())) return {};
    return fmt::format("a common diameter error of {:.3f} % ({:.2f} mm over the campaign's typical {:.2f} m leg, "
                       "below {:.2g} mm)",
                       100.0 * s, mm, c.motion_length_m, 1e3 * c.FloorM());
  }

  std::string Unphysical(const Params& p, int /*runs*/, const Params& /*se*/) const override {
    if (std::abs(Get(p, "s")) > 0.1)
      return fmt::format("both wheels {:.1f}% off their nominal diameter: a unit or configuration error, not wear",
                         100.0 * Get(p, "s"));
    return {};
  }

  // The explained model's E_d, E_b (AdviceContext) turned into wheel
  // diameters (contract: c_L = 2 / (E_d + 1), c_R = 2 / (1 / E_d + 1)) and
  // the wheelbase E_b b.
  std::string ConcreteChange(const Params& p, const AdviceContext& c) const override {
    const double s = Get(p, "s"), f = 1.0 + s;
    const double cl = 2.0 / (c.E_d + 1.0), cr = 2.0 / (1.0 / c.E_d + 1.0);
    return fmt::format(
        "Wheel diameters: both wheels are {:.2f}% {} than the model's. Set wheel_diameter_left_m = {:.5f} and "
        "wheel_diameter_right_m = {:.5f} (the diameters x (1 + s) = x {:.5f}, with E_d = {:.5f}; now {:.5f} / "
        "{:.5f}), wheelbase_m = {:.5f} (E_b = {:.5f}; E_d, E_b {}); or re-measure the wheels on a tape-measured "
        "straight run.",
        100.0 * std::abs(s), s >= 0.0 ? "larger" : "smaller", cl * c.robot.wheel_diameter_left_m * f,
        cr * c.robot.wheel_diameter_right_m * f, f, c.E_d, c.robot.wheel_diameter_left_m,
        c.robot.wheel_diameter_right_m, c.E_b * c.robot.wheelbase_m, c.E_b,
        c.explained ? "fitted jointly with the named effects, not the baseline's" : "of the model compared with");
  }

  void TrueWheels(const Effects& e, int /*run_index*/, double& left, double& right) const override {
    left *= 1.0 + e.scale_s;
    right *= 1.0 + e.scale_s;
  }

  std::string PlainProblem(const Params& p) const override {
    return fmt::format("both wheels are {:.2f}% {} than the model says", 100.0 * std::abs(Get(p, "s")),
                       Get(p, "s") >= 0.0 ? "larger" : "smaller");
  }

  // `diagnose --baseline`: s relative to the given model's own mean
  // diameter.
  Params DescribeGiven(const Params& raw, const GivenContext& g) const override {
    Params out = raw;
    if (const auto it = raw.find("s"); it != raw.end()) out["s"] = (1.0 + it->second) / (1.0 + g.scale) - 1.0;
    return out;
  }
  Params DescribeGivenErrors(const Params& raw_se, const GivenContext& g) const override {
    Params out = raw_se;
    if (const auto it = raw_se.find("s"); it != raw_se.end()) out["s"] = it->second / (1.0 + g.scale);
    return out;
  }

 protected:
  std::string Range(const Effects& e) const override {
    if (!(e.scale_s > -0.5 && e.scale_s < 0.5)) return fmt::format("scale_error.s = {} must be in (-0.5, 0.5)", e.scale_s);
    return {};
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(ScaleError)
