// Exact model of the commanded UMBmark square (contract, "Commanded motion"):
// the controller ends every leg and every spot turn when its odometry, which
// uses the RECORDED parameters, says the target is reached. So the commanded
// wheel rotations are the nominal ones, and the true wheel travel of each
// motion is the nominal travel times D_true / D_recorded of that wheel.
//
//   leg of side L:       nominal travel  left = L,              right = L
//   spot turn of +90 deg (ccw, left):    left = -(b/2)(pi/2),   right = +(b/2)(pi/2)
//   spot turn of -90 deg (cw, right):    left = +(b/2)(pi/2),   right = -(b/2)(pi/2)
//   (b = recorded wheelbase)
//
// A run is leg, turn, leg, turn, leg, turn, leg, turn: Borenstein & Feng's
// robot "made a fourth 90 deg turn after returning to its starting area"
// (section 5), and the OptiOdom runs' ground truth ends at a total rotation
// of about +-2 pi. The final turn can be left out (final_turn = false) for a
// protocol that stops after the fourth leg.
//
// Each motion has constant curvature (both wheels at a fixed speed ratio), so
// it is integrated in ONE exact arc step (DiffDriveStep, Integrator::kArc): no
// small-angle approximation anywhere. Everything is templated on the scalar
// so ceres::Jet differentiates through it (refine_residuals.hpp), and the
// simulator can reuse the motion list with its own per-partition noise.
//
// Return error (Borenstein & Feng eq. 3.1): e = true final pose - odometry
// final pose, both in the run's start frame; the odometry final pose is
// (0, 0, -+2 pi) up to rounding and is computed, not assumed.
//
// Unknowns are RELATIVE to the recorded parameters (what calibrate outputs):
//   E_b = b_true / b_rec,  c_L = D_L,true / D_L,rec,  c_R = D_R,true / D_R,rec
// so E_d = c_R / c_L is relative to the recorded diameter ratio.
#pragma once

#include <optional>
#include <string_view>
#include <vector>

#include "kinematics/diff_drive.hpp"
#include "core/pose2.hpp"

namespace umbmark {

/// cw: the robot turns right (-90 deg) at each corner; ccw: left (contract).
enum class SquareDirection { kCw, kCcw };

const char* SquareDirectionToString(SquareDirection d);
/// "cw" / "ccw" (exactly, lower case); anything else -> nullopt.
std::optional<SquareDirection> SquareDirectionFromString(std::string_view s);

/// One commanded motion: the wheel travels the odometry (recorded
/// parameters) measures when the controller declares the motion done.
struct CommandedMotion {
  enum class Kind { kLeg, kSpotTurn };
  Kind kind = Kind::kLeg;
  double nominal_left_m = 0.0;
  double nominal_right_m = 0.0;
};

/// The motions of one square run of side `side_m` [m] under a recorded
/// wheelbase `recorded_wheelbase_m` [m]. final_turn: whether the run ends with
/// the fourth turn (default, see the file comment). Preconditions: both > 0.
std::vector<CommandedMotion> CommandedSquare(SquareDirection direction, double side_m, double recorded_wheelbase_m,
                                             bool final_turn = true);

/// Executes `motions` on a robot whose true parameters relative to the
/// recorded ones are E_b, c_L, c_R: true wheel travel = c * nominal travel,
/// true wheelbase = E_b * recorded_wheelbase_m. Returns the final pose in the
/// start frame (heading continuous, not wrapped).
template <typename T>
Pose2T<T> ExecuteCommanded(const std::vector<CommandedMotion>& motions, double recorded_wheelbase_m, const T& E_b,
                           const T& c_L, const T& c_R) {
  const T wheelbase = E_b * T(recorded_wheelbase_m);
  Pose2T<T> pose{T(0.0), T(0.0), T(0.0)};
  for (const CommandedMotion& m : motions) {
    pose = DiffDriveStep(pose, c_L * T(m.nominal_left_m), c_R * T(m.nominal_right_m), wheelbase, Integrator::kArc);
  }
  return pose;
}

/// The final pose the odometry computes for `motions` (recorded parameters).
Pose2 OdometryOfCommanded(const std::vector<CommandedMotion>& motions, double recorded_wheelbase_m);

/// Return error e = true - odometry final pose (eq. 3.1) of a run with true
/// relative parameters E_b, c_L, c_R. e.theta is the difference of continuous
/// headings (small for any sensible robot; no wrap, so it stays smooth).
template <typename T>
Pose2T<T> PredictReturnError(const std::vector<CommandedMotion>& motions, double recorded_wheelbase_m,
                             const Pose2& odometry_final, const T& E_b, const T& c_L, const T& c_R) {
  const Pose2T<T> truth = ExecuteCommanded(motions, recorded_wheelbase_m, E_b, c_L, c_R);
  return {truth.x - T(odometry_final.x), truth.y - T(odometry_final.y), truth.theta - T(odometry_final.theta)};
}

/// Convenience: the return error of one square run (double precision).
Pose2 SquareReturnError(SquareDirection direction, double side_m, double recorded_wheelbase_m, double E_b,
                        double c_L, double c_R, bool final_turn = true);

}  // namespace umbmark
