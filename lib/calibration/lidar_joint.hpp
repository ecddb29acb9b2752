// Joint calibration of the wheels, the lidar's mounting pose and the scan
// clock from ordinary driving (Censi, Franchi, Marchionni & Oriolo, T-RO
// 2013, "Simultaneous maximum-likelihood calibration of odometry and sensor
// parameters", extended by the clock): pure maths on wheel samples and
// scan-registration measurements (lidar_pairs.hpp), no files.
//
// Parameters p = [c_L, c_R, b, x, y, yaw, dt]:
//   c_L, c_R  true / nominal wheel diameter (the travel the odometry reports
//             is the nominal diameter's; the true travel is c times it)
//   b         wheelbase [m]
//   x, y, yaw the lidar's pose in the robot frame (axle midpoint, x forward)
//   dt        scan clock offset [s]: header stamp minus the time of the scan
//             (its first ray)
//
// Model of one measurement between keyframe scans stamped t_a, t_b:
//
//     robot_a_T_robot_b = integral of the arcs of the wheel travel over
//                         [t_a - dt, t_b - dt] (travel interpolated linearly)
//     lidar_a_T_lidar_b = M^-1 * robot_a_T_robot_b * M,   M = (x, y, yaw)
//
// residual = sqrt(W) (z - prediction), W^-1 = s^2 * registration covariance +
// k^2 * wheel-noise covariance (the Chong-Kleeman travel variance k^2 |d|
// per wheel, propagated over the interval), with s^2 and k^2 estimated by
// maximum likelihood from the residuals (variance components) between Gauss-
// Newton rounds. Weak priors (prior_*) keep a parameter the drive does not
// excite at its start value instead of making the problem singular; the
// excitation is judged from how far the data shrink each prior.
//
// The covariance is the sandwich H^-1 S H^-1 (H the Gauss-Newton Hessian, S
// the sum of the measurements' score products, lag 0 and 1: consecutive
// measurements share a keyframe scan, so their registration errors are
// correlated). It holds when the noise model is wrong in scale or shape.
// Model-error terms add the registrations' scale error and rotation common
// to a drive (LidarJointOptions::registration_scale_sd,
// registration_rotation_sd), which the data cannot show.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "calibration/lidar_pairs.hpp"
#include "core/pose2.hpp"

namespace umbmark::calibration {

/// Cumulative wheel travel as the odometry reports it (nominal diameters).
struct WheelTravelSample {
  std::int64_t t_ns = 0;
  double left_m = 0.0, right_m = 0.0;
};

/// Index of each parameter in LidarJointFit::covariance.
enum LidarParam : int { kCLeft = 0, kCRight, kWheelbase, kMountX, kMountY, kMountYaw, kTimeOffset, kLidarParams };
/// "c_left", "c_right", "wheelbase_m", "mount_x_m", "mount_y_m", "mount_yaw_rad", "scan_time_offset_s".
const char* LidarParamName(int i);

struct LidarJointParams {
  double c_left = 1.0, c_right = 1.0;  ///< true / nominal diameter
  double wheelbase_m = 0.0;
  Pose2 mount;                         ///< robot_T_lidar (mirrored frame when upside down)
  double time_offset_s = 0.0;          ///< header stamp minus the scan's time
  std::array<double, kLidarParams> Vector() const;
  static LidarJointParams FromVector(const double* p);
};

/// Settings of the fit. Defaults: priors wide enough never to pull a
/// parameter the drive determines (20 % on the wheels, 1 m and pi on the
/// mount, 0.5 s on the clock), a clock searched within +-1 s.
struct LidarJointOptions {
  double prior_wheel_sd = 0.2;       ///< relative sd of the priors on c_L, c_R and b
  double prior_mount_sd_m = 1.0;     ///< sd of the priors on x, y [m]
  double prior_yaw_sd_rad = kPi;     ///< sd of the prior on the yaw [rad]
  double prior_offset_sd_s = 0.5;    ///< sd of the prior on the clock offset [s]
  double max_offset_s = 1.0;         ///< measurements this close to the ends of the wheel data are not used [s]
  double outlier_chi2 = 25.0;        ///< a measurement whose normalised squared residual exceeds this is dropped
  int rounds = 3;                    ///< fit / variance-component rounds
  int max_iterations = 100;          ///< Gauss-Newton iterations per round
  /// Relative sd of a scale error of a drive's registrations (all its
  /// translations read 1 + e long) that no residual can show: it is the
  /// wheels' overall scale, so the fit takes it as theirs. Added to the
  /// covariance as a model-error term along that direction (every length,
  /// c_L, c_R, b, x, y, times 1 + e). The default is measured, not tuned:
  /// on 250 simulated five-minute development drives in a furnished room
  /// (bench/bench_lidar_joint.cpp, seeds 1-200 and 50001-50050, the
  /// registrations as they are now: both ways, occlusion edges skipped) the
  /// variance component that makes the wheelbase's and the diameters' mean
  /// squared normalised error 1, pooled over the three (2.5e-5, 8.2e-5,
  /// 6.3e-5 apart). It was 1.5e-4 from seeds 1-40 before the occlusion edges
  /// were skipped. 0 leaves it out.
  double registration_scale_sd = 6.7e-5;
  /// sd of a rotation common to a drive's registered translations (each
  /// reads turned by r) [rad]: the lidar's yaw takes it as its own (M^-1 D M
  /// with the yaw less r turns every predicted translation by r, nothing
  /// else), so no residual shows it. Added to the yaw's variance. Measured
  /// as above, on the same 250 development drives: 5.7e-5 rad (the fitted
  /// yaw's mean error there is -4.7e-5 rad, t = -4.4; bench_lidar_pairs on
  /// seeds 101-160 finds the registrations' translations turned by +5.3e-5
  /// rad on average, t = 2.5). 0 leaves it out.
  double registration_rotation_sd = 5.7e-5;
  /// Empty when valid, else a message naming the bad field.
  std::string Validate() const;
};

struct LidarJointFit {
  LidarJointParams params;
  /// Row-major kLidarParams x kLidarParams over [c_L, c_R, b, x, y, yaw, dt].
  std::array<double, kLidarParams * kLidarParams> covariance{};
  std::array<double, kLidarParams> prior_sd{};  ///< the weak priors' sd
  double registration_scale = 1.0;  ///< s: registration covariance multiplier found
  double wheel_noise_k = 0.0;       ///< k [m^1/2]: wheel travel noise found
  std::size_t measurements = 0, outliers = 0, unusable = 0;  ///< used, dropped as outliers, outside the wheel data
  double final_cost = 0.0;
  bool converged = false;
  double Sd(int i) const;
};

/// The start values: Censi's first (linear) step for the rotation part
/// (the heading change is linear in c_L/b and c_R/b), the overall scale from
/// the straight stretches, the yaw from the direction the lidar moves in
/// them, the position from a linear fit given the rest, clock 0.
/// `pairs` in the mirrored frame when the lidar is upside down.
struct LinearStart {
  LidarJointParams params;
  double j21 = 0.0, j22 = 0.0;  ///< heading change per metre of left / right travel [rad/m]
  double straight_m = 0.0;      ///< travel in measurements turning less than 0.1 rad
  double turned_rad = 0.0;      ///< sum of |heading change|
};
LinearStart LinearCalibration(const std::vector<WheelTravelSample>& wheels, const std::vector<ScanPair>& pairs,
                              double nominal_wheelbase_m);

/// Fits the parameters. `wheels` in time order, `pairs` in time order (in
/// the mirrored frame when the lidar is upside down: see MirrorPair).
/// Throws InvalidOptions for bad options, QualityGateError when fewer than
/// 10 measurements fall inside the wheel data.
LidarJointFit FitLidarJoint(const std::vector<WheelTravelSample>& wheels, const std::vector<ScanPair>& pairs,
                            const LidarJointParams& start, const LidarJointOptions& options = {});

/// The measurement as an upside-down lidar's mirror image (y and the heading
/// negated): what a lidar mounted the right way up would have measured.
ScanPair MirrorPair(const ScanPair& p);

/// The lidar's motion the model predicts for a measurement (for tests and
/// residual plots).
Pose2 PredictLidarMotion(const std::vector<WheelTravelSample>& wheels, std::int64_t t_a_ns, std::int64_t t_b_ns,
                         const LidarJointParams& p);

}  // namespace umbmark::calibration
