// An effect's per-run simulation hooks (Effect::StartRun, RunEffect; issue
// 28 item 4): a dummy effect defined only here, registered at run time,
// kicks the heading where a motion starts from a standstill and wears the
// left wheel in every step, and the simulator's library path
// (sim::SimulateCampaign) applies both with no other file touched.
// Reference: the closed form. On a straight leg of nominal wheel travel L
// a left wheel travelling (1 - w) times as far turns the robot by w L / b
// (b the wheelbase); the kick adds delta at the leg's start.
#include <catch2/catch.hpp>

#include <cmath>
#include <memory>
#include <variant>

#include "effects/registry.hpp"
#include "simulation/campaign_sim.hpp"
#include "support/effect_campaign.hpp"

using namespace umbmark;
using Catch::Matchers::WithinAbs;

namespace {

/// The run's state of the dummy: counts the starts it kicked and the steps
/// it wore, and draws one number of its own stream per run (which must not
/// shift any other stream).
class NudgeRun final : public effects::RunEffect {
 public:
  NudgeRun(double delta, double w, int* starts, int* steps) : delta_(delta), w_(w), starts_(starts), steps_(steps) {}
  void MotionStart(const effects::SimMotion& m, Pose2& pose) override {
    if (!m.from_standstill || m.turn) return;
    pose.theta += delta_;
    ++*starts_;
  }
  void StepTravel(const effects::SimMotion& /*m*/, const effects::SimStep& /*s*/, double (&travel)[2]) override {
    travel[0] *= 1.0 - w_;
    ++*steps_;
  }

 private:
  double delta_, w_;
  int* starts_;
  int* steps_;
};

/// A kick of delta at every start from standstill and a left wheel worn by
/// w in every step (its values in the class: Effects has no field for an
/// effect added at run time).
class StartNudge final : public effects::Effect {
 public:
  StartNudge(double delta, double w)
      : Effect({.name = "start_nudge",
                .kind = std::nullopt,
                .order = 52,
                .effect_class = effects::EffectClass::kMechanism,
                .definition = "at every start from standstill the heading jumps by delta; the left wheel travels "
                              "(1 - w) times as far",
                .parameters = {},
                .sim_stream = 5000}),
        delta_(delta),
        w_(w) {}
  bool Active(const effects::Effects& /*e*/) const override { return on; }
  std::unique_ptr<effects::RunEffect> StartRun(const effects::Effects& /*e*/,
                                               effects::RandomSource& rng) const override {
    drawn = rng.Normal();
    return std::make_unique<NudgeRun>(delta_, w_, &starts, &steps);
  }
  bool on = false;
  mutable int starts = 0, steps = 0;
  mutable double drawn = 0.0;

 private:
  double delta_, w_;
};

}  // namespace

TEST_CASE("effects: a dummy effect's per-run hooks (StartRun) are simulated in its own file") {
  testing::NoiseFreeCampaign setup = testing::MakeNoiseFreeCampaign(9);  // the closed form holds exactly
  const RobotParams& r = setup.robot;
  sim::CampaignSimOptions& o = setup.options;
  o.effects.bump_rate = 0.5;        // bumps (their own stream) stay the same with the dummy on
  o.effects.bump_sigma = 0.002;
  const double L = setup.leg_m, delta = 0.004, w = 0.01;
  const Manifest& m = setup.manifest;

  auto owned = std::make_unique<StartNudge>(delta, w);
  StartNudge* nudge = owned.get();
  effects::Register(std::move(owned));
  const sim::SimulatedCampaign before = sim::SimulateCampaign(m, o);
  CHECK(nudge->starts == 0);  // inactive: never started
  nudge->on = true;
  const sim::SimulatedCampaign after = sim::SimulateCampaign(m, o);
  // Every run started it once; every start from standstill that is not a
  // spot turn was kicked (a square has 4 legs; back and forth 2).
  CHECK(nudge->starts == 2 * 4 + 2);
  CHECK(nudge->steps > 0);
  CHECK(std::isfinite(nudge->drawn));

  // The bumps come from their own stream: the same with the dummy on.
  CHECK(before.bumps == after.bumps);
  int bumps = 0;
  for (const auto& e : after.bumps)
    for (int b : e) bumps += b;
  CHECK(bumps > 0);
  const double turned[2] = {testing::TurnOverFirstLeg(before, setup), testing::TurnOverFirstLeg(after, setup)};
  // delta + w L / b = 4 + 66.7 mrad (70.667; measured 70.672: the same
  // bumps in both, worn by w too, and the controller's last tick). Without
  // the kick or the wear it would be off by 4 or 67 mrad.
  CHECK_THAT(turned[1] - turned[0], WithinAbs(delta + w * L / r.wheelbase_m, 5e-4));
}
