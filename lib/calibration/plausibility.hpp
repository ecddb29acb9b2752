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

}  // namespace umbmark
