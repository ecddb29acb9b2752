// A small noise-free campaign for the effect-interface tests (a dummy effect
// registered at run time): one square per direction and one back-and-forth
// run of 2 m, no wheel noise, so that closed forms hold exactly.
#pragma once

#include <catch2/catch.hpp>

#include <cstdint>
#include <string>
#include <variant>

#include "core/errors.hpp"
#include "simulation/campaign_sim.hpp"
#include "simulation/effects.hpp"

namespace umbmark::testing {

struct NoiseFreeCampaign {
  RobotParams robot;
  sim::CampaignSimOptions options;
  Manifest manifest;
  double leg_m = 2.0;  ///< the back-and-forth leg
};

inline NoiseFreeCampaign MakeNoiseFreeCampaign(std::uint64_t seed) {
  NoiseFreeCampaign c;
  c.robot.wheelbase_m = 0.3;
  c.robot.wheel_diameter_left_m = c.robot.wheel_diameter_right_m = 0.1;
  c.robot.ticks_per_rev = 4096;
  c.options.seed = seed;
  c.options.square_runs_per_direction = 1;
  c.options.back_and_forth_runs = 1;
  c.options.truth.k_L = c.options.truth.k_R = 0.0;
  c.manifest = sim::StandardCampaignManifest(c.robot, 1.0, c.leg_m, GroundTruthNoise{});
  return c;
}

/// Noise-free simulation options: k = 0, no ground-truth noise, so wheel
/// travel equals distance and an effect's closed form holds exactly.
inline sim::CampaignSimOptions QuietOptions(int square_runs_per_direction, int back_and_forth_runs) {
  sim::CampaignSimOptions o;
  o.truth.k_L = o.truth.k_R = 0.0;
  o.square_runs_per_direction = square_runs_per_direction;
  o.back_and_forth_runs = back_and_forth_runs;
  o.ground_truth = GroundTruthNoise{0.0, 0.0};
  return o;
}

/// A square campaign without ground-truth noise: wheelbase `b`, 0.1 m
/// wheels, squares of `side` and back-and-forth legs of `leg` [m].
inline Manifest QuietManifest(double b, double side, double leg) {
  RobotParams r;
  r.wheelbase_m = b;
  r.wheel_diameter_left_m = r.wheel_diameter_right_m = 0.1;
  return sim::StandardCampaignManifest(r, side, leg, GroundTruthNoise{0.0, 0.0});
}

/// The message an effect specification is refused with ("" when accepted).
inline std::string EffectSpecError(const std::string& spec) {
  sim::Effects e;
  try {
    sim::ParseEffectSpec(spec, e);
  } catch (const InvalidOptions& x) {
    return x.what();
  }
  return {};
}

inline const TrajectoryRun& FirstBackAndForthRun(const sim::SimulatedCampaign& c) {
  REQUIRE(c.data.size() == 2);
  REQUIRE(std::holds_alternative<TrajectoryData>(c.data[1]));
  REQUIRE_FALSE(std::get<TrajectoryData>(c.data[1]).runs.empty());
  return std::get<TrajectoryData>(c.data[1]).runs.front();
}

/// The ground truth's heading change over the first back-and-forth leg, up
/// to the first sample with the leg's nominal travel (the encoders count
/// the same ticks whatever the ground truth did).
inline double TurnOverFirstLeg(const sim::SimulatedCampaign& c, const NoiseFreeCampaign& setup) {
  const TrajectoryRun& run = FirstBackAndForthRun(c);
  REQUIRE(run.ticks_left.size() == run.t_s.size());
  REQUIRE(run.gt_theta_rad.size() == run.t_s.size());
  const double per_tick = setup.robot.MetresPerTickLeft();
  std::size_t end = 0;
  while (end + 1 < run.t_s.size() &&
         0.5 * per_tick * static_cast<double>(run.ticks_left[end] + run.ticks_right[end]) < setup.leg_m - 1e-3)
    ++end;
  return run.gt_theta_rad[end] - run.gt_theta_rad[0];
}

}  // namespace umbmark::testing
