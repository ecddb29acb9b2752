// The covariance diagonals a ros2_control diff_drive_controller publishes
// with its odometry (pose_covariance_diagonal, twist_covariance_diagonal:
// x, y, z, roll, pitch, yaw), derived from the wheel noise model of Chong &
// Kleeman (1997, eq. 4): each wheel's travel error has variance k^2 |travel|.
// Derivation in docs/ros2.md. Driving straight at speed v with updates at
// rate f, each wheel travels ds = v / f per update, so with k2 = k_L^2 + k_R^2:
//   twist:  var(v_x)   = k2 v f / 4      (v_x = (dR + dL) / 2 * f)
//           var(w_z)   = k2 v f / b^2    (w_z = (dR - dL) / b * f)
//   pose (one update's increment, what a filter in differential mode uses):
//           var(x)     = k2 ds / 4
//           var(yaw)   = k2 ds / b^2
//           var(y)     = ds^2 var(yaw) / 3     (heading error random-walking over the update)
// Entries planar odometry does not measure (z, roll, pitch and their
// rates) get kUnmeasuredVariance; the lateral velocity, zero by the
// non-holonomic constraint, gets kConstraintVariance.
#pragma once

#include <array>
#include <string>

namespace umbmark {

struct OdometryCovarianceOptions {
  double rate_hz = 50.0;   ///< odometry update rate (diff_drive_controller's publish_rate default)
  double speed_mps = 0.5;  ///< driving speed the variances are stated for
  /// Empty when valid, else a message naming the bad field.
  std::string Validate() const;
};

struct OdometryCovariance {
  std::array<double, 6> pose{};   ///< x, y, z, roll, pitch, yaw
  std::array<double, 6> twist{};  ///< vx, vy, vz, wx, wy, wz
};

inline constexpr double kUnmeasuredVariance = 1e6;
inline constexpr double kConstraintVariance = 1e-9;

/// Diagonals for wheel noise k_L, k_R [m^1/2] and wheelbase b [m]. Throws
/// InvalidOptions for bad options or non-finite/negative inputs.
OdometryCovariance OdometryCovarianceFromWheelNoise(double k_L, double k_R, double wheelbase_m,
                                                    const OdometryCovarianceOptions& options);

}  // namespace umbmark
