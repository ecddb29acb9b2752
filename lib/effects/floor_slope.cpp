// floor_slope (outside the contract, see gt_yaw_misalignment.cpp): a tilted
// floor; the robot slides g metres per metre of wheel travel ((|l| + |r|)/2)
// towards the direction `dir` [rad] of its start frame.
#include <fmt/format.h>

#include "effects/effect.hpp"

namespace umbmark::effects {
namespace {

class FloorSlope final : public Effect {
 public:
  FloorSlope()
      : Effect({.name = "floor_slope",
                .kind = EffectKind::kFloorSlope,
                .order = 101,
                .effect_class = EffectClass::kMechanism,
                .in_contract = false,
                .definition = "(outside the contract) the robot slides g metres per metre of wheel travel towards "
                              "direction dir of its start frame",
                .parameters = {{"g", &Effects::slope_g, "m/m"}, {"dir", &Effects::slope_dir, "rad"}}}) {}

  // A direction without a slope is no slope.
  bool Active(const Effects& e) const override { return e.slope_g > 0.0; }

 protected:
  std::string Range(const Effects& e) const override {
    if (!(e.slope_g >= 0.0 && e.slope_g < 0.5)) return fmt::format("floor_slope.g = {} must be in [0, 0.5)", e.slope_g);
    return {};
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(FloorSlope)
