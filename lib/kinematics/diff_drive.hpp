// Differential-drive dead reckoning: pose update from left/right wheel travel.
//
// Two integrators:
//  - kArc (default): exact for constant curvature between samples, i.e. both
//    wheels at constant speed ratio over the step (the standard assumption
//    for an encoder sample). With ds = (dR + dL)/2 and dtheta = (dR - dL)/b the
//    chord is ds * sinc(dtheta/2) in direction theta + dtheta/2:
//        x += ds * sinc(dtheta/2) * cos(theta + dtheta/2)
//        y += ds * sinc(dtheta/2) * sin(theta + dtheta/2)
//    which is the closed form x += ds/dtheta (sin(theta+dtheta) - sin(theta))
//    rewritten so that it is numerically safe at and near dtheta = 0 (a
//    Taylor series is used for |dtheta/2| < 1e-4, where it is exact to
//    double precision). Default because it has no discretisation error, so
//    the results do not depend on the logging rate.
//  - kMidpoint: the same without the sinc factor (second-order accurate,
//    error O(ds dtheta^2 / 24) per step). Used by the OptiOdom reference
//    implementation and many robot drivers; select it to reproduce them.
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <string_view>

#include "core/pose2.hpp"

namespace umbmark {

enum class Integrator { kArc, kMidpoint };

inline const char* IntegratorToString(Integrator i) { return i == Integrator::kArc ? "arc" : "midpoint"; }
inline std::optional<Integrator> IntegratorFromString(std::string_view s) {
  if (s == "arc") return Integrator::kArc;
  if (s == "midpoint") return Integrator::kMidpoint;
  return std::nullopt;
}

/// sin(u)/u, safe at u = 0 (works for ceres::Jet too).
template <typename T>
T Sinc(const T& u) {
  using std::abs;
  using std::sin;
  if (abs(u) < 1e-4) {
    const T u2 = u * u;
    return T(1.0) - u2 / T(6.0) + u2 * u2 / T(120.0);
  }
  return sin(u) / u;
}

/// One dead-reckoning step with wheel travels d_left, d_right [m] and
/// wheelbase b [m]. Returns the new pose (theta is NOT wrapped: continuous
/// heading is kept so total rotation can be read off).
template <typename T>
Pose2T<T> DiffDriveStep(const Pose2T<T>& p, const T& d_left, const T& d_right, const T& wheelbase,
                        Integrator integrator = Integrator::kArc) {
  using std::cos;
  using std::sin;
  const T ds = (d_right + d_left) * T(0.5);
  const T dtheta = (d_right - d_left) / wheelbase;
  const T half = dtheta * T(0.5);
  const T chord = integrator == Integrator::kArc ? ds * Sinc(half) : ds;
  const T heading = p.theta + half;
  return {p.x + chord * cos(heading), p.y + chord * sin(heading), p.theta + dtheta};
}

}  // namespace umbmark
