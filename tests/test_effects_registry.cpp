// The effects' registry and interface (issue 28 item 4): every built-in
// effect in the contract's order, lookup by name, run-time registration, and
// the practical floors as pose sizes at the campaign's own speeds (closed
// forms: a clock tau moves the pose by tau v and the heading by tau w; a
// common diameter error s adds s L over a leg of L).
#include <catch2/catch.hpp>

#include <memory>
#include <string>

#include "core/errors.hpp"
#include "diagnosis/campaign_scale.hpp"
#include "diagnosis/pieces.hpp"
#include "effects/registry.hpp"
#include "simulation/campaign_sim.hpp"
#include "simulation/effects.hpp"

using namespace umbmark;
using Catch::Matchers::WithinRel;

TEST_CASE("effects: every built-in effect is registered once, in the contract's order") {
  const auto& all = effects::All();
  REQUIRE(all.size() >= 19);
  // The contract's table (interface.md "Effects"), then the outside
  // effects, then the parameter errors of `diagnose --baseline`.
  const char* expected[] = {"scale_error",      "turn_scrub",        "direction_asymmetry", "castor_kick",
                            "bump_outliers",    "correlated_noise",  "parameter_drift",     "gt_offset",
                            "time_offset",      "standstill_motion", "motion_noise_floor",  "run_time_offset",
                            "stop_slide",       "castor_swivel",     "gt_yaw_misalignment", "floor_slope",
                            "wheelbase_error",  "diameter_ratio_error", "wheel_noise_error"};
  for (std::size_t i = 0; i < std::size(expected); ++i) {
    INFO(i);
    CHECK(all[i]->Name() == expected[i]);
    CHECK(effects::Find(expected[i]) == all[i]);
  }
  CHECK(effects::Find("no_such_effect") == nullptr);
  CHECK(sim::ContractEffects().size() == 14);
  CHECK(sim::ParameterErrorEffects().size() == 3);
  CHECK(effects::Find("gt_offset")->Class() == effects::EffectClass::kMeasurement);
  CHECK(effects::Find("stop_slide")->Class() == effects::EffectClass::kMechanism);
  CHECK(effects::Find("motion_noise_floor")->Random());
  CHECK_FALSE(effects::Find("wheel_noise_error")->Simulated());
  CHECK(effects::Find("stop_slide")->TypicalSize("d") == 0.065);
  // A name is taken once.
  struct Clash : effects::Effect {
    Clash() : Effect({.name = "scale_error", .kind = std::nullopt, .definition = "", .parameters = {}}) {}
  };
  CHECK_THROWS_AS(effects::Register(std::make_unique<Clash>()), InvalidOptions);
}

TEST_CASE("effects: a clock's practical floor is a pose size at the campaign's speed") {
  const effects::Effect& tau = *effects::Find("time_offset");
  effects::CampaignScale walk;  // 0.2 m/s, 0.2 rad/s: the old fixed 1.5 ms floor
  CHECK_FALSE(tau.PracticalFloor({{"tau", 1.4e-3}}, walk).empty());
  CHECK(tau.PracticalFloor({{"tau", 1.6e-3}}, walk).empty());
  // The case: at 2 m/s a 1.4 ms clock is 2.8 mm and must be nameable.
  effects::CampaignScale fast;
  fast.speed_mps = 2.0;
  CHECK(tau.PracticalFloor({{"tau", 1.4e-3}}, fast).empty());
  CHECK_FALSE(tau.PracticalFloor({{"tau", 0.14e-3}}, fast).empty());  // 0.28 mm, 0.028 mrad
  // Turning fast: 1 ms at 1 rad/s is 1 mrad of heading.
  effects::CampaignScale turning;
  turning.turn_rate_radps = 1.0;
  CHECK(tau.PracticalFloor({{"tau", 1e-3}}, turning).empty());
  // --negligible 0.5 doubles the floors; 0 switches them off.
  effects::CampaignScale lax = fast;
  lax.negligible = 0.5;
  CHECK_FALSE(tau.PracticalFloor({{"tau", 0.28e-3}}, lax).empty());
  lax.negligible = 0.0;
  CHECK(tau.PracticalFloor({{"tau", 1e-6}}, lax).empty());
  // A scale error over the campaign's legs.
  const effects::Effect& s = *effects::Find("scale_error");
  CHECK_FALSE(s.PracticalFloor({{"s", 2e-4}}, walk).empty());  // 0.2 mm over 1 m
  effects::CampaignScale long_legs;
  long_legs.motion_length_m = 2.0;
  CHECK(s.PracticalFloor({{"s", 2e-4}}, long_legs).empty());  // 0.4 mm over 2 m
}

TEST_CASE("effects: the campaign's speeds, turn rate and leg length come from its runs") {
  RobotParams r;
  r.wheelbase_m = 0.3;
  r.wheel_diameter_left_m = r.wheel_diameter_right_m = 0.1;
  r.ticks_per_rev = 2048;
  sim::CampaignSimOptions o;
  o.seed = 3;
  o.square_runs_per_direction = 2;
  o.back_and_forth_runs = 2;
  o.speed_m_s = 0.5;
  o.turn_rate_rad_s = 0.8;
  const Manifest m = sim::StandardCampaignManifest(r, 2.0, 2.0, GroundTruthNoise{});
  const sim::SimulatedCampaign c = sim::SimulateCampaign(m, o);
  const effects::CampaignScale scale = diag::CampaignScaleOf(diag::BuildCampaign(c.manifest, c.data), 0.25);
  // Constant-speed motions as commanded (the ramps' partial intervals are
  // few: the medians are the commanded values within 2 %).
  CHECK_THAT(scale.speed_mps, WithinRel(0.5, 0.02));
  CHECK_THAT(scale.turn_rate_radps, WithinRel(0.8, 0.02));
  CHECK_THAT(scale.motion_length_m, WithinRel(2.0, 0.02));
  CHECK(scale.negligible == 0.25);
}
