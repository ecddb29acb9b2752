// Exact Jacobians of one constant-curvature wheel step (Chong & Kleeman
// eqs. 14-17) and the pose-error transition matrix (eq. 21 = Kelly's Psi).
//
// A step moves the left wheel L and the right wheel R [m] (wheelbase B):
//   theta_k = theta_{k-1} + (R - L)/B                                  (14)
//   r_k     = (B/2)(L + R)/(L - R)     (NEGATIVE for a left turn)      (15)
//
// Misprints corrected here (checked against automatic differentiation of
// DiffDriveStep in tests/test_covariance_jacobians.cpp):
//  * eq. 17 prints "r_k cos(theta_k)" and "r_k sin(theta_k)" in the first
//    two rows; differentiating eq. 14 gives (r_k/B) cos(theta_k) and
//    (r_k/B) sin(theta_k) (eq. 22 has the /B).
//  * eq. 17 row 2, column 2 prints -B L_k/(L_k-R_k)^2 [cos th_k - cos th_{k-1}];
//    d r_k/d R_k = +B L_k/(L_k-R_k)^2, so the sign is +, as eq. 22 has it.
#pragma once

#include <cmath>

#include <Eigen/Core>

#include "core/pose2.hpp"

namespace umbmark {

/// Pose-error transition from pose `from` to pose `to` along any path
/// (eq. 21, Kelly eq. 11 "Psi"): an error [dx, dy, dtheta] at `from` becomes
/// Phi * error at `to`:
///   Phi = [1 0 -(y_to - y_from); 0 1 (x_to - x_from); 0 0 1].
inline Eigen::Matrix3d PoseErrorTransition(const Pose2& from, const Pose2& to) {
  Eigen::Matrix3d phi = Eigen::Matrix3d::Identity();
  phi(0, 2) = -(to.y - from.y);
  phi(1, 2) = to.x - from.x;
  return phi;
}

/// d(pose_k)/d(pose_{k-1}) of one step (eq. 16), for a step that ends at
/// pose `to` from `from` (valid for any L, R, including straight lines).
inline Eigen::Matrix3d StepStateJacobian(const Pose2& from, const Pose2& to) { return PoseErrorTransition(from, to); }

/// d(pose_k)/d[L_k, R_k] of one arc step (eq. 17 with the misprints fixed),
/// for L != R. theta0 = theta_{k-1}.
inline Eigen::Matrix<double, 3, 2> ArcStepWheelJacobian(double theta0, double L, double R, double B) {
  const double thk = theta0 + (R - L) / B;  // (14)
  const double r = 0.5 * B * (L + R) / (L - R);  // (15)
  const double d2 = (L - R) * (L - R);
  const double ds = std::sin(theta0) - std::sin(thk);
  const double dc = std::cos(thk) - std::cos(theta0);
  Eigen::Matrix<double, 3, 2> J;
  J(0, 0) = -B * R / d2 * ds + r / B * std::cos(thk);
  J(0, 1) = B * L / d2 * ds - r / B * std::cos(thk);
  J(1, 0) = -B * R / d2 * dc + r / B * std::sin(thk);
  J(1, 1) = B * L / d2 * dc - r / B * std::sin(thk);
  J(2, 0) = -1.0 / B;
  J(2, 1) = 1.0 / B;
  return J;
}

}  // namespace umbmark
