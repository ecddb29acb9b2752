// A yaw-rate gyro against the scan-registered ground truth. Model of the
// reading (sensor_msgs/msg/Imu angular_velocity.z):
//
//     measured = gyro_scale * true_yaw_rate + gyro_bias + noise
//
// The bias is the mean reading while the robot stands still (the wheels'
// pauses); the scale is the least-squares ratio of the bias-corrected
// integrated rate over each run to the run's scan-registered heading change
// (sum G_k dtheta_k / sum dtheta_k^2). With the scale known, the integrated
// heading of each run is a second reference for its turns.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace umbmark::scan {

struct GyroSample {
  std::int64_t t_ns = 0;
  double rate_rad_s = 0.0;
};

/// One run's time span and its heading change from scan registration.
struct GyroRun {
  std::int64_t t_start_ns = 0, t_end_ns = 0;
  double scan_heading_change_rad = 0.0;
};

struct GyroCalibration {
  double bias_rad_s = 0.0;
  double bias_sd_rad_s = 0.0;  ///< standard error of the bias (reading scatter / sqrt(still samples))
  double scale = 1.0;
  std::size_t still_samples = 0;
  /// Per run: the gyro's heading change, (integral of measured - bias) / scale.
  std::vector<double> gyro_heading_change_rad;
};

/// `samples` in time order; `still` the [begin, end] spans where the robot
/// stands still. Throws std::invalid_argument when no sample lies in a still
/// span, or the runs do not turn (no scale can be found).
GyroCalibration CalibrateGyro(const std::vector<GyroSample>& samples,
                              const std::vector<std::pair<std::int64_t, std::int64_t>>& still,
                              const std::vector<GyroRun>& runs);

/// Integral of (rate - bias) over [t0, t1] (trapezoids; the ends interpolated).
double IntegrateRate(const std::vector<GyroSample>& samples, double bias, std::int64_t t0, std::int64_t t1);

}  // namespace umbmark::scan
