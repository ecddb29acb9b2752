// Angle helpers: wrapping to (-pi, pi] and degree/radian conversion.
#pragma once

#include <cmath>
#include <numbers>

namespace umbmark {

inline constexpr double kPi = std::numbers::pi;

/// Wraps an angle to (-pi, pi].
inline double WrapAngle(double a) {
  double w = std::remainder(a, 2.0 * kPi);  // in [-pi, pi]
  if (w <= -kPi) w += 2.0 * kPi;
  return w;
}

inline constexpr double Deg2Rad(double deg) { return deg * kPi / 180.0; }
inline constexpr double Rad2Deg(double rad) { return rad * 180.0 / kPi; }

}  // namespace umbmark
