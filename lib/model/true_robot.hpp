// The true robot: the physical robot relative to the parameters its
// odometry uses, the correction factors that map one onto the other, the
// exact step the true robot takes, and the encoder controller's stop rule.
// Both simulators (Monte Carlo plan, logged campaign runs) and the UMBmark
// calibration use these; nothing else writes them out.
//
//   E_d = (D_R / D_L)_true / (D_R / D_L)_recorded    diameter ratio error
//   E_b = b_true / b_recorded                         wheelbase error
//   s   = scale error: both true diameters (1 + s) times the model's
//   c_L = 2 / (E_d + 1),  c_R = 2 / (1/E_d + 1)       (B&F eqs. 4.31, 4.32)
//   D_L,true = c_L (1 + s) D_L,   D_R,true = c_R (1 + s) D_R
// c_R / c_L = E_d and (c_L + c_R) / 2 = 1 when s = 0: E_d changes the ratio
// and keeps the mean diameter.
#pragma once

#include <cmath>
#include <string>

#include "core/pose2.hpp"
#include "kinematics/diff_drive.hpp"

namespace umbmark {

/// Correction factor of the left wheel diameter, c_L = 2/(E_d+1) (eq. 4.31).
inline double CorrectionLeft(double E_d) { return 2.0 / (E_d + 1.0); }
/// Correction factor of the right wheel diameter, c_R = 2/(1/E_d+1) (eq. 4.32).
inline double CorrectionRight(double E_d) { return 2.0 / (1.0 / E_d + 1.0); }

/// The physical robot relative to the parameters its odometry uses.
struct TrueRobot {
  /// Wheel diameter ratio error (Borenstein & Feng): true D_R/D_L over the
  /// nominal ratio. > 0. Default 1.
  double E_d = 1.0;
  /// Wheelbase error: true wheelbase / nominal. > 0. Default 1.
  double E_b = 1.0;
  /// scale_error s: both true diameters (1 + s) times the model's. > -1. Default 0.
  double scale = 0.0;

  /// True left / right wheel travel per nominal metre: c (1 + s).
  double WheelFactorLeft() const { return CorrectionLeft(E_d) * (1.0 + scale); }
  double WheelFactorRight() const { return CorrectionRight(E_d) * (1.0 + scale); }

  /// Empty when valid, else a message naming the bad field.
  std::string Check() const;
};

/// One exact constant-curvature step of the true robot: wheel ground travel
/// l, r [m], wheelbase b [m], the heading change (r - l)/b scaled by
/// `heading_factor` (1 - k inside spot turns with turn_scrub k; 1 otherwise).
/// With heading_factor 1 this is DiffDriveStep (kArc).
inline Pose2 TrueStep(const Pose2& p, double l, double r, double wheelbase, double heading_factor) {
  const double ds = 0.5 * (l + r);
  const double dtheta = (r - l) / wheelbase * heading_factor;
  const double half = 0.5 * dtheta;
  const double chord = ds * Sinc(half);
  const double heading = p.theta + half;
  return {p.x + chord * std::cos(heading), p.y + chord * std::sin(heading), p.theta + dtheta};
}

/// How far below T + 1 the logged-run simulator stops a wheel moving
/// backward [ticks], so that floor(p) reads T afterwards (its next motion
/// starts from that count). 1e-9 ticks is ~1e-13 m of travel.
inline constexpr double kStopBelowTicks = 1e-9;

/// The encoder controller's stop rule (contract, "Commanded motion"): a
/// wheel at continuous position p [ticks] whose count reads `count` and must
/// reach `target` stops the instant the count reaches it: at p = target
/// moving forward, at the top of tick `target` moving backward (p = target +
/// 1 - below; the Monte Carlo plan uses the limit below = 0 because it keeps
/// the counts separately, the logged-run simulator kStopBelowTicks), and
/// stays at p when the target is the count it reads.
inline double EncoderStopPosition(double target, double count, double p, double below = 0.0) {
  if (target > count) return target;
  if (target < count) return target + 1.0 - below;
  return p;
}

}  // namespace umbmark
