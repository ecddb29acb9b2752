// Closed-form motion covariance of a spot turn about the axle centre (Chong
// & Kleeman section 5.2, eq. 28): heading goes from theta0 to theta0 + phi,
// the wheels roll L = -(B/2) phi and R = +(B/2) phi.
//
// Misprint corrected: section 5.2 states the limits as L -> (B/2)(th_k - th_0)
// and R -> (B/2)(th_0 - th_k); with eq. 14 (th_k - th_0 = (R - L)/B) those
// give th_k - th_0 = -(th_k - th_0). The correct limits swap L and R (as
// above). Eq. 28 itself matches the correct limits (tests check it against
// eq. 25 and against numerical propagation, with k_L != k_R).
#pragma once

#include <cmath>

#include "error_models/wheel_noise.hpp"

namespace umbmark {

/// Eq. (28), as a basis: Cov(U) = k_L^2 A_L + k_R^2 A_R.
inline CovarianceBasis TurnCovarianceBasis(double phi, double theta0, double B) {
  const double thk = theta0 + phi;
  const double sg = phi > 0.0 ? 1.0 : (phi < 0.0 ? -1.0 : 0.0);  // sgn as defined after eq. 25
  PoseCovariance common = PoseCovariance::Zero();
  common(0, 0) = B / 32.0 * (2.0 * phi - std::sin(2.0 * theta0) + std::sin(2.0 * thk)) * sg;
  common(1, 1) = B / 32.0 * (2.0 * phi + std::sin(2.0 * theta0) - std::sin(2.0 * thk)) * sg;
  common(2, 2) = std::abs(phi) / (2.0 * B);
  common(0, 1) = common(1, 0) = B / 32.0 * (std::cos(2.0 * theta0) - std::cos(2.0 * thk)) * sg;
  // Off-diagonal heading terms carry (k_R^2 - k_L^2).
  const double e13 = 0.25 * (std::sin(thk) - std::sin(theta0)) * sg;
  const double e23 = 0.25 * (std::cos(theta0) - std::cos(thk)) * sg;
  CovarianceBasis b;
  b.A_L = common;
  b.A_R = common;
  b.A_L(0, 2) = b.A_L(2, 0) = -e13;
  b.A_L(1, 2) = b.A_L(2, 1) = -e23;
  b.A_R(0, 2) = b.A_R(2, 0) = e13;
  b.A_R(1, 2) = b.A_R(2, 1) = e23;
  return b;
}

}  // namespace umbmark
