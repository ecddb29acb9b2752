// gt_yaw_misalignment (outside the contract; the blind benchmark's check
// that the diagnosis answers `unexplained` rather than a confident wrong
// name): the ground truth's heading is the true heading + delta (a
// motion-capture rigid body defined with a yaw offset); its position is
// right.
#include <cmath>

#include <fmt/format.h>

#include "effects/effect.hpp"

namespace umbmark::effects {
namespace {

class GtYawMisalignment final : public Effect {
 public:
  GtYawMisalignment()
      : Effect({.name = "gt_yaw_misalignment",
                .kind = EffectKind::kGtYawMisalignment,
                .order = 100,
                .effect_class = EffectClass::kMeasurement,
                .in_contract = false,
                .definition = "(outside the contract) ground-truth heading = true heading + delta; position right",
                .parameters = {{"delta", &Effects::yaw_delta, "rad"}}}) {}

  void GroundTruthPoint(const Effects& e, double& /*dx*/, double& /*dy*/, double& dtheta) const override {
    dtheta += e.yaw_delta;
  }

 protected:
  std::string Range(const Effects& e) const override {
    if (!(std::abs(e.yaw_delta) < 1.0))
      return fmt::format("gt_yaw_misalignment.delta = {} must be in (-1, 1) rad", e.yaw_delta);
    return {};
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(GtYawMisalignment)
