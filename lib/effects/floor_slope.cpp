// floor_slope (outside the contract, see gt_yaw_misalignment.cpp): a tilted
// floor; the robot slides g metres per metre of wheel travel ((|l| + |r|)/2)
// towards the direction `dir` [rad] of its start frame.
#include <cmath>

#include <fmt/format.h>

#include "effects/effect.hpp"

namespace umbmark::effects {
namespace {

/// A run's slide downhill: g (|l| + |r|) / 2 per step towards dir.
class SlopeRun final : public RunEffect {
 public:
  SlopeRun(double g, double dir) : g_(g), cos_(std::cos(dir)), sin_(std::sin(dir)) {}
  bool StepDrift(const double (&travel)[2], double& dx, double& dy) override {
    const double slope = g_ * 0.5 * (std::abs(travel[0]) + std::abs(travel[1]));
    dx = slope * cos_;
    dy = slope * sin_;
    return true;
  }

 private:
  double g_, cos_, sin_;
};

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

  std::unique_ptr<RunEffect> StartRun(const Effects& e, RandomSource& /*rng*/) const override {
    return std::make_unique<SlopeRun>(e.slope_g, e.slope_dir);
  }

 protected:
  std::string Range(const Effects& e) const override {
    if (!(e.slope_g >= 0.0 && e.slope_g < 0.5)) return fmt::format("floor_slope.g = {} must be in [0, 0.5)", e.slope_g);
    return {};
  }
};

}  // namespace
}  // namespace umbmark::effects

UMBMARK_EFFECT(FloorSlope)
