// Odometry covariance diagonals from wheel noise (see odometry_covariance.hpp).
#include "error_models/odometry_covariance.hpp"

#include <cmath>

#include <fmt/format.h>

#include "core/errors.hpp"

namespace umbmark {

std::string OdometryCovarianceOptions::Validate() const {
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz)) return fmt::format("rate_hz = {}: must be > 0", rate_hz);
  if (!(speed_mps > 0.0) || !std::isfinite(speed_mps)) return fmt::format("speed_mps = {}: must be > 0", speed_mps);
  return {};
}

OdometryCovariance OdometryCovarianceFromWheelNoise(double k_L, double k_R, double wheelbase_m,
                                                    const OdometryCovarianceOptions& o) {
  if (const std::string err = o.Validate(); !err.empty()) throw InvalidOptions(err);
  if (!(k_L >= 0.0) || !(k_R >= 0.0) || !std::isfinite(k_L) || !std::isfinite(k_R))
    throw InvalidOptions(fmt::format("k_L = {}, k_R = {}: must be finite and >= 0", k_L, k_R));
  if (!(wheelbase_m > 0.0) || !std::isfinite(wheelbase_m))
    throw InvalidOptions(fmt::format("wheelbase_m = {}: must be > 0", wheelbase_m));
  const double k2 = k_L * k_L + k_R * k_R;
  const double ds = o.speed_mps / o.rate_hz;  // travel per update
  const double b2 = wheelbase_m * wheelbase_m;
  OdometryCovariance c;
  const double var_yaw = k2 * ds / b2;
  c.pose = {k2 * ds / 4.0, ds * ds * var_yaw / 3.0, kUnmeasuredVariance, kUnmeasuredVariance, kUnmeasuredVariance,
            var_yaw};
  c.twist = {k2 * o.speed_mps * o.rate_hz / 4.0, kConstraintVariance, kUnmeasuredVariance, kUnmeasuredVariance,
             kUnmeasuredVariance, k2 * o.speed_mps * o.rate_hz / b2};
  return c;
}

}  // namespace umbmark
