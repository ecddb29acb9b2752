// `umbmark plan`: the runs to drive for a target precision (docs/plan.md).
//
// A design is a square side, runs per direction, back-and-forth runs and
// their length, free paths and pauses (motions.hpp). Its predicted 95 %
// half-widths come from information.hpp for the calibration `calibrate`
// recommends on it (outputs_use): plain least squares on the square runs
// with ground truth along the path, classic UMBmark with ground truth at
// the end points; k_L, k_R from fit-noise (REML) over every run. A target
// is met when the predicted half-width is at most the target.
//
// Search: for every square side on a grid (0.5 m steps from min_side_m up
// to max_side_m, and max_side_m itself) the calibration covariance of one
// cw and one ccw run is computed once (runs of one kind are identical, so
// n of them have 1/n of its covariance); the fewest runs per direction
// meeting the calibration targets follow in closed form; with a k target,
// back-and-forth runs of every length on the same grid are added (each
// count searched by bisection, the information being monotone in it) and
// more squares are tried while they can still be cheaper. The design with
// the least driving time wins (ties: fewer runs).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/robot.hpp"
#include "error_models/wheel_noise.hpp"
#include "planning/information.hpp"
#include "planning/motions.hpp"

namespace umbmark::planning {

enum class GroundTruthKind { kMocap, kScan, kTape };
const char* GroundTruthKindToString(GroundTruthKind k);
std::optional<GroundTruthKind> GroundTruthKindFromString(std::string_view s);

/// 95 % half-widths per quantity; empty where not targeted or not known.
struct HalfWidths {
  std::optional<double> E_d, E_b, scale;  ///< fractions
  std::optional<double> k_L, k_R;         ///< [m^1/2]
};

struct PlanOptions {
  /// The recorded robot (what its odometry uses). Required (Check()).
  RobotParams robot;
  /// Wheel noise the prediction assumes (a fit-noise result or stated).
  WheelNoise noise;
  GroundTruthKind ground_truth = GroundTruthKind::kMocap;
  /// The ground truth's noise per measured pose; empty: by kind, mocap
  /// 0.3 mm / 1 mrad, scan 5 mm / 5 mrad, tape 2 mm / 5 mrad.
  std::optional<double> gt_sigma_xy_m, gt_sigma_theta_rad;
  /// Targets: 95 % half-widths (> 0). At least one is required. target_k
  /// applies to k_L and k_R each.
  std::optional<double> target_E_d, target_E_b, target_scale, target_k;
  /// Free floor space: the longest square side and back-and-forth length [m]
  /// (default 3 m; at least min_side_m).
  double max_side_m = 3.0;
  /// Shortest side or length tried [m] (default 0.5 m, > 0).
  double min_side_m = 0.5;
  /// Driving time allowed [s] (default: none).
  std::optional<double> max_time_s;
  /// Speeds and pauses (motions.hpp; default 0.3 m/s, 1 rad/s, 1 s pauses).
  MotionTiming timing;
  /// Rate of the logged samples the fits see [Hz] (default 20, > 0). Only
  /// the ground truth's white noise averages over it.
  double rate_hz = 20.0;
  /// Fewest runs per square direction (default 3: fit-noise needs two per
  /// group, the plain fit's run-clustered covariance four runs in all;
  /// calibrate warns below 4).
  int min_runs_per_direction = 3;
  /// Most runs per direction / back-and-forth runs searched (default 200).
  int max_runs = 200;
  /// Empty when valid, else a message naming the bad field.
  std::string Check() const;
  GroundTruthModel GroundTruth() const;
};

struct PlanDesign {
  double square_side_m = 0.0;
  int runs_cw = 0, runs_ccw = 0;
  int back_and_forth_runs = 0;
  double back_and_forth_length_m = 0.0;  ///< 0 when there are none
  std::vector<std::string> free_paths;   ///< path SPECs (predict), may be empty
  double pause_s = 1.0;
  double time_s = 0.0;  ///< driving time, pauses included [s]
};

struct PlanResult {
  PlanDesign design;
  HalfWidths predicted;  ///< the targeted quantities (and, for information, the others known)
  /// Which target decided the number of runs (the binding one).
  std::string binding;
  /// Empty when the design meets every target; else the target that cannot
  /// be met and why (the app exits 3).
  std::string unmet;
  std::string method;  ///< "plain_least_squares" or "umbmark_mean": what calibrate recommends on it
  std::vector<std::string> notes;
  bool ok() const { return unmet.empty(); }
};

/// Plans a design. Throws InvalidOptions (naming the field) for bad options.
PlanResult Plan(const PlanOptions& options);

/// Predicted half-widths of a given design (every quantity it determines).
HalfWidths PredictDesign(const PlanDesign& design, const PlanOptions& options);

/// The design's motions, run after run (cw and ccw squares alternating,
/// then back and forth, then free paths), each motion tagged with its run.
struct DesignMotion {
  int run = 0;  ///< 1-based
  RunKind kind = RunKind::kSquareCw;
  Motion motion;
};
std::vector<DesignMotion> DesignMotions(const PlanDesign& design, const PlanOptions& options);

}  // namespace umbmark::planning
