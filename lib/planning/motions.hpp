// What a robot drives for a planned design (`umbmark plan`): motions
// (lines, spot turns, arcs, pauses; the contract's `--motions` list), the
// runs a design is made of, and the samples the fits see along a run
// (cumulative wheel travel at a fixed rate, as a logged run has them).
//
// A run starts and ends standing still for max(pause_s, 1 s) (the start
// pose is measured at standstill; the diagnosis needs the standstills)
// and pauses pause_s between motions:
//   square (side L, cw or ccw): 4 x (line L, pause, turn -+pi/2, pause)
//   back and forth (length D):  line D, pause, line -D
//   free path (a path SPEC as for `predict`): its segments, pauses between
// Lines and arcs drive at `speed` [m/s] (axle centre), spot turns at
// `turn_rate` [rad/s]; no acceleration phase (the time is a lower bound by
// the acceleration time of each motion).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "error_models/path_spec.hpp"
#include "kinematics/odometry.hpp"

namespace umbmark::planning {

struct Motion {
  enum class Kind { kLine, kTurn, kArc, kPause };
  Kind kind = Kind::kPause;
  double distance_m = 0.0;  ///< line: signed distance (< 0 backwards)
  double angle_rad = 0.0;   ///< turn, arc: signed angle (+ = ccw)
  double radius_m = 0.0;    ///< arc: radius of the axle centre's path (> 0)
  double speed = 0.0;       ///< line, arc [m/s]; turn [rad/s]
  double duration_s = 0.0;  ///< pause
  /// Wheel travel of the motion [m] for wheelbase b (0 for a pause).
  WheelSegment Wheels(double wheelbase_m) const;
  /// How long it takes [s].
  double Duration() const;
};

const char* MotionKindToString(Motion::Kind k);

/// The kinds of run a design holds.
enum class RunKind { kSquareCw, kSquareCcw, kBackAndForth, kFreePath };
const char* RunKindToString(RunKind k);

struct MotionTiming {
  double speed_m_s = 0.3;      ///< lines and arcs [m/s], > 0
  double turn_rate_rad_s = 1.0;  ///< spot turns [rad/s], > 0
  double pause_s = 1.0;        ///< between motions [s], >= 0
  /// Standstill at the start and end of every run: max(pause_s, this) [s].
  double end_pause_min_s = 1.0;
  double EndPause() const { return pause_s > end_pause_min_s ? pause_s : end_pause_min_s; }
};

/// The motions of one run. `size` is the side (square), the length (back
/// and forth); `spec` the path of a free path (ignored otherwise).
std::vector<Motion> RunMotions(RunKind kind, double size, const std::vector<PathSegment>& spec, double wheelbase_m,
                               const MotionTiming& timing);

double MotionsDuration(const std::vector<Motion>& motions);

/// A path SPEC's segments as motions (line, turn, or arc of constant
/// curvature; an arc with equal and opposite wheel travel is a turn).
std::vector<Motion> MotionsOfPath(const std::vector<PathSegment>& path, double wheelbase_m, const MotionTiming& timing);

/// Cumulative wheel travel at t = 0, 1/rate, ... up to the end (the last
/// sample at the end exactly), every motion at constant wheel speeds.
WheelTravel SampleMotions(const std::vector<Motion>& motions, double wheelbase_m, double rate_hz);

}  // namespace umbmark::planning
