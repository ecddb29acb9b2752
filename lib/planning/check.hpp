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
  /// Wheel noise; empty: fitted to the campaign (fit-noise, REML, no intervals; see CheckResult::calibration_noise).
  std::optional<WheelNoise> noise;
  /// The ground truth's noise; empty: the manifest's, else motion-capture
  /// defaults (0.3 mm, 1 mrad) with a note.
  std::optional<GroundTruthModel> ground_truth;
  /// Correlation above which two quantities count as not separated (default 0.95).
  double max_correlation = 0.95;
  /// Timing of the suggested additions (motions.hpp).
  MotionTiming timing;
  double rate_hz = 20.0;  ///< logging rate assumed for the additions [Hz]
  /// The correction the caller found (calibrate, diagnose: E_d and E_b
  /// factors). When set, `record_more` says how many more square runs
  /// would determine it; empty (default): no record_more for it.
  std::optional<double> correction_E_d, correction_E_b;
  /// A correction counts as determined when its predicted 95 % half-width
  /// is at most this fraction of |E - 1| (default 0.5, in (0, 1]).
  double determined_fraction = 0.5;
  /// Most extra runs per direction record_more searches (default 100, >= 1).
  int max_extra_runs = 100;
  std::string Check() const;
};

struct Confusion {
  /// "parameters" (E_b, E_d, scale), "noise" (k_L, k_R) or "effects"
  /// (diagnosis effects, against E_b, E_d or each other).
  std::string kind;
  std::vector<std::string> what;  ///< parameter or effect names
  std::string add;                ///< the smallest addition that separates them
  double correlation = 1.0;       ///< now (1: not excited / not determined)
};

/// How many more square runs (the campaign's side, as many cw as ccw)
/// would determine a correction the caller found (CheckOptions).
struct RecordMore {
  std::string quantity;           ///< "E_d" | "E_b"
  double correction = 0.0;        ///< E - 1
  double half_width = 0.0;        ///< predicted 95 % half-width now
  /// Extra runs per direction that bring the half-width to
  /// determined_fraction |E - 1|; 0 when more than max_extra_runs would
  /// be needed (the correction is within the noise of any practical design).
  int extra_runs_per_direction = 0;
  double half_width_after = 0.0;  ///< with them (or with max_extra_runs)
  double time_s = 0.0;            ///< their driving time [s]
  double side_m = 0.0;
};

struct CheckResult {
  HalfWidths predicted;  ///< every quantity the campaign determines
  std::string method;    ///< plain_least_squares | umbmark_mean
  WheelNoise noise;      ///< used for the prediction of k_L, k_R (and for the calibration when given)
  /// Used for the calibration's prediction: `noise` when given; when
  /// fitted, the fit to the return errors' positions alone (the plain fit
  /// and classic UMBmark see positions only).
  WheelNoise calibration_noise;
  bool noise_fitted = false;
  GroundTruthModel ground_truth;
  int square_runs_cw = 0, square_runs_ccw = 0, other_runs = 0;
  std::vector<Confusion> cannot_separate;
  /// For each correction given (CheckOptions) that these runs do not
  /// determine: the runs that would.
  std::vector<RecordMore> record_more;
  std::vector<std::string> notes;
};

/// One sentence for a person: what cannot be told apart and what to add
/// (calibrate's and diagnose's "cannot tell apart" messages).
std::string ConfusionMessage(const Confusion& c);
/// One sentence: the correction, its half-width, the runs that would
/// determine it (calibrate's "record more runs" message).
std::string RecordMoreMessage(const RecordMore& r);

/// Throws InvalidOptions for bad options, InputError for data it cannot use
/// (no square run, ticks without ticks_per_rev).
CheckResult CheckCampaign(const RobotParams& robot, const std::vector<CheckExperiment>& experiments,
                          const CheckOptions& options);

}  // namespace umbmark::planning
