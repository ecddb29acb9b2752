// gt_offset (contract): the ground truth reports the point (dx, dy) of the
// robot frame instead of the axle midpoint.
#include <cmath>

#include <fmt/format.h>

#include "effects/effect.hpp"

namespace umbmark::effects {
namespace {

class GtOffset final : public Effect {
 public:
  GtOffset()
      : Effect({.name = "gt_offset",
                .kind = EffectKind::kGtOffset,
                .order = 7,
                .effect_class = EffectClass::kMeasurement,
                .definition = "ground truth reports the point (dx, dy) of the robot frame instead of the axle midpoint",
                .parameters = {{"dx", &Effects::gt_dx, "m", 0.01}, {"dy", &Effects::gt_dy, "m", 0.01}},
                .mean_terms = {kTermDx, kTermDy},
                .separated_by = SeparatingExperiment::kTurnsWhileDriving,
                .separated_rank = 1}) {}

  // The marker's distance is a position already: below the position floor.
  std::string PracticalFloor(const Params& p, const CampaignScale& c) const override {
    const double r = std::hypot(Size(p, "dx"), Size(p, "dy"));
    if (!(c.negligible > 0.0) || !(r < c.FloorM())) return {};
    return fmt::format("a marker {:.2f} mm off the axle midpoint (below {:.2g} mm)", 1e3 * r, 1e3 * c.FloorM());
  }

  std::string Unphysical(const Params& p, int /*runs*/, const Params& /*se*/) const override {
    const double r = std::hypot(Get(p, "dx"), Get(p, "dy"));
    if (r > 0.3) return fmt::format("a ground-truth marker {:.0f} mm from the axle midpoint: off the robot", 1e3 * r);
    return {};
  }

  std::string ConcreteChange(const Params& p, const AdviceContext& /*c*/) const override {
    const double dx = Get(p, "dx"), dy = Get(p, "dy");
    return fmt::format(
        "Motion capture: the tracked point is at (dx, dy) = ({:+.1f}, {:+.1f}) mm from the axle midpoint in the "
        "robot frame (x forward, y left). Enter that offset as the marker's position in the rigid body (move the "
        "rigid body's origin by ({:+.1f}, {:+.1f}) mm, onto the axle midpoint), or subtract it from the recorded "
        "poses.",
        1e3 * dx, 1e3 * dy, -1e3 * dx, -1e3 * dy);
  }

  void GroundTruthPoint(const Effects& e, double& dx, double& dy, double& /*dtheta*/) const override {
    dx += e.gt_dx;
    dy += e.gt_dy;
  }

  std::string PlainProblem(const Params& p) const override {
    return fmt::format("the motion capture tracks a point ({:+.1f}, {:+.1f}) mm from the axle midpoint",
                       1e3 * Get(p, "dx"), 1e3 * Get(p, "dy"));
  }

 protected:
  std::string Range(const Effects& e) const override {
    if (!(std::abs(e.gt_dx) < 10.0 && std::abs(e.gt_dy) < 10.0))
      return fmt::format("gt_offset (dx, dy) = ({}, {}) must be within 10 m", e.gt_dx, e.gt_dy);
    return {};
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(GtOffset)
