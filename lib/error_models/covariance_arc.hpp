// Closed-form motion covariance of one constant-curvature arc (Chong &
// Kleeman eq. 25): the pose covariance at the end of an arc on which the left
// wheel rolls L and the right wheel R [m] (any signs), starting at heading
// theta0, caused by white wheel noise of variance k^2 |travel| (eq. 4).
//
// Derivation (checked in tests against many-segment propagation of the exact
// step Jacobians and against Kelly's integral): a travel error dL at a point
// u in [0, 1] along the arc moves the end pose by
//   J_L(u) = [cos th(u)/2 + (y1 - y(u))/B, sin th(u)/2 - (x1 - x(u))/B, -1/B]
//   J_R(u) = [cos th(u)/2 - (y1 - y(u))/B, sin th(u)/2 + (x1 - x(u))/B, +1/B]
// so Cov(U) = int_0^1 k_L^2 |L| J_L J_L^T + k_R^2 |R| J_R J_R^T du. Eq. (25)
// is this integral in closed form and is printed correctly.
//
// Numerics: eq. 25 has (L - R)^3 in a denominator; its terms grow like
// 1/dtheta^3 and cancel to O(1), losing about log10(1/|dtheta|^3) digits.
// Below |dtheta| = kArcQuadratureBelowRad the integral is evaluated instead
// with Gauss-Legendre quadrature of the stable integrand above (the chord
// x1 - x(u) computed with sinc), which is exact to rounding there because
// the integrand is a low-frequency trigonometric polynomial in u.
#pragma once

#include "error_models/wheel_noise.hpp"

namespace umbmark {

/// |dtheta| = |R - L| / B [rad] below which the quadrature replaces eq. 25.
/// At this value eq. 25 still agrees with the quadrature to ~1e-14 relative
/// (tests/test_covariance_arc.cpp checks the seam from both sides).
inline constexpr double kArcQuadratureBelowRad = 0.25;

/// Eq. (25) in closed form, as printed (no threshold; for tests and for
/// |R - L|/B not small). Precondition: L != R, B > 0.
CovarianceBasis ArcCovarianceBasisClosedForm(double L, double R, double theta0, double B);

/// The same integral by Gauss-Legendre quadrature of the stable integrand
/// (valid for any L, R; exact to rounding for |R - L|/B <= 1).
CovarianceBasis ArcCovarianceBasisQuadrature(double L, double R, double theta0, double B);

/// Motion covariance basis of one arc: eq. (25) when |R - L|/B >=
/// kArcQuadratureBelowRad, quadrature otherwise. Any L, R (lines, spot turns,
/// pivots on one wheel, reversing). Precondition: B > 0.
CovarianceBasis ArcCovarianceBasis(double L, double R, double theta0, double B);

inline PoseCovariance ArcCovariance(double L, double R, double theta0, double B, const WheelNoise& noise) {
  return ArcCovarianceBasis(L, R, theta0, B).Evaluate(noise);
}

}  // namespace umbmark
