// Closed-form motion covariance of a straight line (Chong & Kleeman section
// 5.1, eqs. 26 and 27): both wheels roll D [m] (D < 0 drives backwards) at
// constant heading theta, wheelbase B, white wheel noise k^2 |travel|.
//
// Misprint corrected: eq. 26 prints Cov(U)_22 with "D^2/(3B^2) sin^2(theta)";
// the limit of eq. 25 (and eq. 27 at theta = 0, which has D^3/(3B^2)) needs
// cos^2(theta). Checked numerically in tests/test_covariance_closed_forms.cpp.
// For D < 0 the printed |D| factors stay |D| and the D inside the brackets is
// signed; eq. 27 is eq. 26 at theta = 0 with D > 0.
#pragma once

#include <cmath>

#include "error_models/wheel_noise.hpp"

namespace umbmark {

/// Eq. (26) (corrected), as a basis: Cov(U) = k_L^2 A_L + k_R^2 A_R.
inline CovarianceBasis LineCovarianceBasis(double D, double theta, double B) {
  const double c = std::cos(theta), s = std::sin(theta);
  const double aD = std::abs(D);
  const double q = D * D / (3.0 * B * B);
  auto make = [&](double sign) {  // sign = +1 for the left wheel, -1 for the right
    PoseCovariance P;
    P(0, 0) = aD * (0.25 * c * c + sign * D / (2.0 * B) * s * c + q * s * s);
    P(1, 1) = aD * (0.25 * s * s - sign * D / (2.0 * B) * s * c + q * c * c);
    P(2, 2) = aD / (B * B);
    P(0, 1) = P(1, 0) =
        aD * ((0.125 - D * D / (6.0 * B * B)) * std::sin(2.0 * theta) - sign * D / (4.0 * B) * std::cos(2.0 * theta));
    P(0, 2) = P(2, 0) = aD * (-sign * c / (2.0 * B) - D / (2.0 * B * B) * s);
    P(1, 2) = P(2, 1) = aD * (-sign * s / (2.0 * B) + D / (2.0 * B * B) * c);
    return P;
  };
  CovarianceBasis b;
  b.A_L = make(+1.0);
  b.A_R = make(-1.0);
  return b;
}

/// Eq. (27): the line along the x axis from a known pose, D >= 0.
inline PoseCovariance LineCovarianceAlongX(double D, double B, const WheelNoise& n) {
  const double sum = n.k_R * n.k_R + n.k_L * n.k_L, diff = n.k_R * n.k_R - n.k_L * n.k_L;
  PoseCovariance P;
  P << D / 4.0 * sum, D * D / (4.0 * B) * diff, D / (2.0 * B) * diff,  //
      D * D / (4.0 * B) * diff, D * D * D / (3.0 * B * B) * sum, D * D / (2.0 * B * B) * sum,  //
      D / (2.0 * B) * diff, D * D / (2.0 * B * B) * sum, D / (B * B) * sum;
  return P;
}

}  // namespace umbmark
