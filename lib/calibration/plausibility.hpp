// Plausibility gates on a UMBmark result, checked before it is printed or
// written: a result no robot can have (non-finite numbers, a non-positive
// wheelbase or diameter, a correction factor outside (0.5, 2)) is a failure
// with the reason and hints at the usual causes (millimetres given as metres,
// swapped encoder channels, a wrong --side); degenerate data that still give
// a usable result (one run per direction, identical runs, no error at all)
// give warnings that the command prints and puts into the JSON `warnings`.
#pragma once

#include <string>
#include <vector>

#include "calibration/umbmark.hpp"
#include "core/runs.hpp"

namespace umbmark {

struct PlausibilityReport {
  /// Why the result cannot be used; non-empty: the command exits 3.
  std::vector<std::string> failures;
  /// What to check (with failures).
  std::vector<std::string> hints;
  /// Degenerate or thin data; the result stands but says so.
  std::vector<std::string> warnings;
  bool ok() const { return failures.empty(); }
  /// "reason; reason (check: hint; hint)" for an error message.
  std::string Message() const;
};

/// Multipliers (E_b, c_L, c_R) outside (kMinMultiplier, kMaxMultiplier)
/// mean the odometry's parameters would be more than halved or doubled: no
/// real calibration is that far off.
constexpr double kMinMultiplier = 0.5;
constexpr double kMaxMultiplier = 2.0;

/// Corrections larger than UMBmark can support (correction_support.hpp;
/// docs/safety.md): a failure when the first-order formulas' bias at the
/// estimate (exact square model) exceeds kBiasFailFraction of the
/// correction |E - 1|, the data's 95 % half-width and a floor; a warning
/// (second pass) when it only exceeds the half-width and a smaller floor.
constexpr double kBiasFailFraction = 0.25;
constexpr double kBiasFailFloorEb = 0.002, kBiasFailFloorEd = 0.0005;
constexpr double kBiasWarnFloorEb = 0.001, kBiasWarnFloorEd = 0.0002;
/// Reversed labels: the centres sit kMirrorRatio times (in squared
/// distance) closer to the other direction's diagonals, and off their own
/// ones with p < kMirrorP (CorrectionSupport::p_off_labels).
constexpr double kMirrorRatio = 4.0;
constexpr double kMirrorP = 0.001;

/// Gates and warnings for a classic UMBmark result.
PlausibilityReport CheckUmbmarkPlausibility(const UmbmarkSummary& s);

/// Adds failures when refined parameters (wheelbase, diameters) are not
/// finite and positive, or their ratio to the recorded ones leaves
/// (kMinMultiplier, kMaxMultiplier).
void CheckRefinedPlausibility(const RobotParams& recorded, const RobotParams& refined, PlausibilityReport& report);

/// Explicit check for swapped left/right encoder channels on trajectories:
/// the odometry's total rotation ((s_R - s_L)/b over the run) must turn the
/// way the ground truth and the cw/ccw label say. Returns the number of
/// square runs whose odometry turns the other way (then the channels, or
/// the ticks' sign, are swapped).
int CountMirroredRuns(const TrajectoryData& data, const RobotParams& recorded);

/// Unit mix-ups seen in the data before any fit; each returns a message
/// (empty when fine). Return errors: the median return position error of
/// the cw/ccw runs is at least kMaxErrorPerSide of the side (errors in
/// millimetres written as metres, or a side too small).
constexpr double kMaxErrorPerSide = 0.5;
std::string CheckReturnErrorScale(const std::vector<ReturnError>& errors, double side_m);
/// Trajectories: the median net wheel travel ((s_L + s_R)/2) of a square
/// run against 4 * side, outside (1/kTravelRatio, kTravelRatio): a wrong
/// side, ticks_per_rev or wheel diameter (e.g. in millimetres).
constexpr double kTravelRatio = 2.0;
std::string CheckTravelScale(const TrajectoryData& data, const RobotParams& recorded, double side_m);

}  // namespace umbmark
