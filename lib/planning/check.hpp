// `umbmark plan --check MANIFEST`: what a recorded campaign determines
// (docs/plan.md). The same information as `plan` (information.hpp), built
// from the recorded runs themselves (their wheel travel and where they have
// ground truth) instead of a design:
//   - predicted_ci95: the 95 % half-widths of E_d, E_b, scale for the
//     calibration calibrate recommends on the square runs (plain least
//     squares with trajectories, classic UMBmark with return errors), and of
//     k_L, k_R for fit-noise over every run with ground truth at both ends;
//   - cannot_separate: pairs the design confuses. Parameters: the
//     calibration's parameters whose estimates correlate beyond
//     `max_correlation`, k_L against k_R likewise, the overall scale where
//     it is not determined at all. Diagnosis effects (contract names): the
//     effect's footprint on the ground truth (its derivative, like a column
//     of the calibration's Jacobian) against the calibration parameters and
//     the other effects; an effect whose footprint lies within
//     `max_correlation` of theirs (the cosine of the angle between it and
//     their span) cannot be told apart from them, one with no footprint is
//     not excited. Effects checked: scale_error, direction_asymmetry,
//     castor_kick, gt_offset, time_offset (with ground truth along the path).
//     For each, the smallest addition that separates it: the cheapest of a
//     few candidate run sets (squares in the missing direction, back and
//     forth runs, circles both ways, ground truth along the path), each in
//     the fewest runs that bring the correlation below the threshold.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/robot.hpp"
#include "core/runs.hpp"
#include "error_models/wheel_noise.hpp"
#include "planning/information.hpp"
#include "planning/motions.hpp"
#include "planning/plan.hpp"

namespace umbmark::planning {

/// One experiment of the campaign, read by the caller.
struct CheckExperiment {
  ExperimentKind kind = ExperimentKind::kSquare;
  double side_m = 0.0, distance_m = 0.0;
  std::string label;                        ///< for messages (the file)
  const TrajectoryData* trajectories = nullptr;  ///< one of the two
  const EndpointData* endpoints = nullptr;
};

struct CheckOptions {
  /// Wheel noise; empty: fitted to the campaign (fit-noise, REML, no intervals).
  std::optional<WheelNoise> noise;
  /// The ground truth's noise; empty: the manifest's, else motion-capture
  /// defaults (0.3 mm, 1 mrad) with a note.
  std::optional<GroundTruthModel> ground_truth;
  /// Correlation above which two quantities count as not separated (default 0.95).
  double max_correlation = 0.95;
  /// Timing of the suggested additions (motions.hpp).
  MotionTiming timing;
  double rate_hz = 20.0;  ///< logging rate assumed for the additions [Hz]
  std::string Check() const;
};

struct Confusion {
  std::vector<std::string> what;  ///< parameter or effect names
  std::string add;                ///< the smallest addition that separates them
  double correlation = 1.0;       ///< now (1: not excited / not determined)
};

struct CheckResult {
  HalfWidths predicted;  ///< every quantity the campaign determines
  std::string method;    ///< plain_least_squares | umbmark_mean
  WheelNoise noise;      ///< used for the prediction
  bool noise_fitted = false;
  GroundTruthModel ground_truth;
  int square_runs_cw = 0, square_runs_ccw = 0, other_runs = 0;
  std::vector<Confusion> cannot_separate;
  std::vector<std::string> notes;
};

/// Throws InvalidOptions for bad options, InputError for data it cannot use
/// (no square run, ticks without ticks_per_rev).
CheckResult CheckCampaign(const RobotParams& robot, const std::vector<CheckExperiment>& experiments,
                          const CheckOptions& options);

}  // namespace umbmark::planning
