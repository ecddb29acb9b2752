// Campaign simulator behind `umbmark simulate`: for every experiment of a
// campaign manifest it simulates runs of a true robot (systematic errors
// E_d, E_b, wheel noise k_L, k_R, encoder ticks, ground truth with
// measurement noise) with any of the contract's effects (effects.hpp), and
// returns the campaign in the contract's formats (manifest + trajectory or
// endpoint CSV per experiment; formats/campaign_writer.hpp writes them).
//
// The true robot relative to the manifest's [robot] (what the odometry uses):
//   D_L,true = c_L D_L (1 + s),  D_R,true = c_R D_R (1 + s) (1 + r i),
//   c_L = 2/(E_d + 1), c_R = 2/(1/E_d + 1)     (B&F eqs. 4.31, 4.32; contract)
//   b_true = E_b b
// Runs per experiment (file order; parameter_drift counts runs over the
// whole campaign, experiments in manifest order):
//   square:          square_runs_per_direction cw and as many ccw runs,
//                    alternating cw, ccw, cw, ...; one run = pause, then four
//                    times (leg of side_m, pause, spot turn of -+90 deg, pause)
//   back_and_forth:  back_and_forth_runs runs of pause, distance_m forward,
//                    pause, distance_m backward, pause
//   free:            when a template trajectory is given for the experiment
//                    (the manifest's file, read by the caller), one run per
//                    template run replaying its wheel travel and timing
//                    (the commanded wheel rotations are the recorded ones);
//                    otherwise free_runs figure-eights: pause, a full ccw
//                    circle of radius free_radius_m, pause, a full cw circle,
//                    pause.
// Legs run at speed_m_s, spot turns at turn_rate_rad_s, arcs with the outer
// wheel at speed_m_s. Samples every 1/sample_rate_hz.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "core/runs.hpp"
#include "simulation/effects.hpp"

namespace umbmark::sim {

/// The physical robot's systematic errors and wheel noise (see file comment).
struct CampaignTruth {
  /// Wheel diameter ratio error relative to the manifest's ratio. > 0. Default 1.
  double E_d = 1.0;
  /// Wheelbase error: true / manifest wheelbase. > 0. Default 1.
  double E_b = 1.0;
  /// Random wheel noise constants k_L, k_R [m^1/2] (Chong & Kleeman eq. 4).
  /// >= 0. Default 0.001 each.
  double k_L = 0.001, k_R = 0.001;

  std::string Check() const;
};

struct CampaignSimOptions {
  CampaignTruth truth;
  Effects effects;
  /// Seed of every random process (noise, bumps, encoder phases, ground truth).
  std::uint64_t seed = 1;
  /// Runs per direction of each square experiment (>= 1). Default 10.
  int square_runs_per_direction = 10;
  /// Runs of each back_and_forth experiment (>= 1). Default 20.
  int back_and_forth_runs = 20;
  /// Runs of each free experiment without a template (>= 1). Default 4.
  int free_runs = 4;
  /// Logging rate [Hz] (> 0). Default 20 (as the OptiOdom data).
  double sample_rate_hz = 20.0;
  /// Leg speed [m/s] (> 0). Default 0.3.
  double speed_m_s = 0.3;
  /// Spot-turn rate [rad/s] (> 0). Default 1.0.
  double turn_rate_rad_s = 1.0;
  /// Standstill before, between and after motions [s] (>= 0). Default 1.0.
  /// With 0 the diagnosis cannot see where motions start.
  double pause_s = 1.0;
  /// Radius of the free figure-eight circles [m] (> wheelbase / 2). Default 1.0.
  double free_radius_m = 1.0;
  /// Ground-truth measurement noise; empty: the manifest's [ground_truth],
  /// or noise-free ground truth when the manifest has none.
  std::optional<GroundTruthNoise> ground_truth;
  /// Whether the written manifest states [ground_truth] (with the noise
  /// used). Default true; false makes `diagnose` estimate it.
  bool state_ground_truth = true;
  /// Write square experiments as endpoint CSV (return errors e = ground
  /// truth - odometry, eq. 3.1) instead of trajectories. Default false.
  bool endpoint_squares = false;
  /// Upper bound on the samples of the whole campaign (checked up front,
  /// before any memory is taken; each sample costs about 150 bytes in memory
  /// and in the CSV). Default 20 million (about 3 GB).
  double max_samples = 2e7;

  std::string Check() const;
};

/// A simulated campaign in memory.
struct SimulatedCampaign {
  Manifest manifest;  ///< experiments with `file` as in the input manifest
  /// Per experiment: the trajectory or endpoint data written to its file.
  std::vector<ExperimentData> data;
  GroundTruthNoise ground_truth_noise;  ///< what was applied
  int total_runs = 0;
  std::uint64_t seed = 0;
  /// Per experiment and run: number of bumps drawn (left + right), for tests.
  std::vector<std::vector<int>> bumps;
};

/// Simulates every experiment of `manifest`. `free_templates[i]`, when
/// present, is the trajectory data that free experiment i replays (indices
/// as manifest experiments; may be shorter or empty). Throws InvalidOptions
/// for bad options (including parameter_drift making a diameter <= 0) and
/// InputError for a template the robot cannot convert (ticks without
/// ticks_per_rev).
SimulatedCampaign SimulateCampaign(const Manifest& manifest, const CampaignSimOptions& options,
                                   const std::vector<std::optional<TrajectoryData>>& free_templates = {});

/// The number of samples SimulateCampaign would produce (sum over runs of
/// duration x sample rate, or the template's samples). Cheap: no run is planned.
double EstimateCampaignSamples(const Manifest& manifest, const CampaignSimOptions& options,
                               const std::vector<std::optional<TrajectoryData>>& free_templates = {});

/// The truth behind a campaign (seed, true robot, effects with their
/// parameters, ground-truth noise, run counts) as JSON.
nlohmann::json CampaignTruthJson(const SimulatedCampaign& campaign, const CampaignSimOptions& options);

/// The standard campaign of the blind benchmark: one square experiment of
/// side `side_m` (file square.csv) and one back_and_forth experiment of
/// `distance_m` (file fwd_back.csv) for `robot`, with `ground_truth` noise.
Manifest StandardCampaignManifest(const RobotParams& robot, double side_m, double distance_m,
                                  const std::optional<GroundTruthNoise>& ground_truth);

}  // namespace umbmark::sim
