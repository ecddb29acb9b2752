// `umbmark calibrate-lidar`: the wheels, the lidar's mounting pose, the scan
// clock and the gyro from one ordinary drive, no motion capture and no
// mounting pose given (contract section "Calibration from a bag without
// motion capture"). Steps:
//   1. register the scans into keyframe measurements (lidar_pairs.hpp);
//      drop those the scene leaves open, refuse a corridor naming it;
//   2. tell a mirrored lidar from swapped wheels by the sign of the turns
//      (scans against wheels, and the gyro against both);
//   3. start values from the linear (Censi) step, then the joint fit
//      (lidar_joint.hpp);
//   4. the gyro's scale, bias and time offset against the heading changes;
//   5. the overall scale from the lidar's ranges, or from a measured
//      distance;
//   6. per parameter, whether the drive excited it, and what to drive.
// Pure computation on in-memory samples; no files.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "calibration/lidar_joint.hpp"
#include "calibration/lidar_pairs.hpp"
#include "core/pose2.hpp"
#include "core/robot.hpp"
#include "scan/gyro_calibration.hpp"
#include "scan/laser_scan.hpp"

namespace umbmark::calibration {

/// The lidar's mount as /tf_static gives it (for comparison only).
struct StaticMount {
  Pose2 pose;               ///< planar pose (the mirrored frame's yaw when upside down)
  bool upside_down = false; ///< roll pi
  std::string frames;       ///< "base_link -> laser"
};

struct LidarCalibrationInput {
  std::vector<WheelTravelSample> wheels;  ///< travel as the odometry reports it (nominal robot), time order
  std::vector<scan::LaserScan> scans;     ///< header stamps, time order
  std::vector<scan::GyroSample> gyro;     ///< empty without a gyro; same clock as the wheels
  RobotParams nominal;                    ///< what the odometry used
  std::optional<StaticMount> tf_mount;
  std::optional<double> distance_m;       ///< measured distance between where the drive starts and ends
};

enum class Excitation { kDetermined, kWeak, kNotExcited };
const char* ExcitationToString(Excitation e);  ///< "determined", "weak", "not_excited"

struct ParameterExcitation {
  std::string key;            ///< contract key: wheelbase_m, wheel_diameter_left_m, ..., gyro_scale
  Excitation level = Excitation::kDetermined;
  double ci95_half = 0.0;     ///< half-width of the 95 % interval (relative for wheelbase, diameters, gyro scale)
  double target = 0.0;        ///< the half-width counted as determined (same units)
  bool relative = false;
  std::string what_to_drive;  ///< empty when determined
};

/// Settings of the gyro's fit against the scans (FitGyroToScans).
struct GyroFitOptions {
  /// Fit the gyro's time offset with its scale and bias (where the drive's
  /// rate changes enough to tell it); false fits scale and bias alone.
  bool fit_delay = true;
  /// Relative sd of a scale error common to a drive's registered heading
  /// changes (every heading change reads 1 + g times the truth), which the
  /// gyro's scale takes as its own and no residual shows: added to the
  /// scale's variance as a model-error term. The default is measured, not
  /// tuned: on 250 simulated five-minute development drives
  /// (bench/bench_lidar_joint.cpp, seeds 1-200 and 50001-50050) the variance
  /// component that makes the gyro scale's mean squared normalised error 1
  /// (its mean error there is -3.0e-5, t = -7.1; bench_lidar_pairs on seeds
  /// 101-160 finds the registered heading changes 2.6e-5 long on average,
  /// t = 4.1). 0 leaves it out.
  double heading_scale_sd = 2.6e-5;
  /// Empty when valid, else a message naming the bad field.
  std::string Validate() const;
};

/// The gyro against the scans' heading changes.
struct GyroFit {
  double scale = 1.0, bias_rad_s = 0.0;
  double scale_sd = 0.0, bias_sd = 0.0;
  std::optional<double> time_offset_s;  ///< the gyro's stamp minus the time of the motion it measures
  double time_offset_sd = 0.0;
  std::size_t measurements = 0;         ///< scan measurements inside the gyro's data
};

/// Fits the gyro's scale, bias and (options.fit_delay) time offset to the
/// heading changes of the scan measurements: the integral of the reading over
/// each measurement's interval (the scan stamps less `scan_time_offset_s`) is
/// scale * heading change + bias * duration - scale * tau * (rate at the end -
/// rate at the start). Least squares with the lag-1 sandwich covariance
/// (consecutive measurements share a scan), plus the model-error term.
/// `gyro` in time order. nullopt when fewer than 10 measurements fall inside
/// the gyro's data or they do not tell the scale from the bias.
std::optional<GyroFit> FitGyroToScans(const std::vector<scan::GyroSample>& gyro, const std::vector<ScanPair>& pairs,
                                      double scan_time_offset_s, const GyroFitOptions& options = {});

/// Settings. Defaults: the targets of a 5-minute drive (wheelbase 0.3 %,
/// diameters 0.2 %, mount 5 mm and 0.1 deg, clock 5 ms, gyro scale 0.3 %)
/// count as determined; up to 20 times them as weak.
struct LidarCalibrationOptions {
  PairOptions pairs;
  LidarJointOptions fit;
  double max_open_fraction = 0.3;  ///< refuse when more of the measurements leave a direction open (a corridor)
  double min_drive_s = 30.0;       ///< refuse a shorter drive
  double target_wheelbase_rel = 0.003, target_diameter_rel = 0.002, target_position_m = 0.005;
  double target_yaw_rad = Deg2Rad(0.1), target_offset_s = 0.005, target_gyro_scale_rel = 0.003;
  double weak_factor = 20.0;       ///< a half-width up to this times the target is weak
  GyroFitOptions gyro;
  /// Empty when valid, else a message naming the bad field.
  std::string Validate() const;
};

struct LidarCalibration {
  RobotParams parameters;             ///< corrected wheelbase and diameters
  double wheel_separation_multiplier = 1.0, left_wheel_radius_multiplier = 1.0, right_wheel_radius_multiplier = 1.0;
  Pose2 mount;                        ///< robot_T_lidar (x, y, yaw; the mirrored frame's yaw when upside down)
  bool upside_down = false;
  std::array<double, 2> x_ci95{}, y_ci95{}, yaw_ci95{};
  double time_offset_s = 0.0;
  std::array<double, 2> time_offset_ci95{};
  std::optional<double> gyro_scale, gyro_bias_rad_s;
  double gyro_scale_sd = 0.0, gyro_bias_sd = 0.0;
  /// The gyro's stamp minus the time of the motion it measures [s] (fitted
  /// with its scale and bias; absent when the drive's rate never changes).
  std::optional<double> gyro_time_offset_s;
  double gyro_time_offset_sd = 0.0;
  /// Covariance over covariance_order (row-major): wheelbase_m,
  /// wheel_diameter_left_m, wheel_diameter_right_m, mount x_m, y_m, yaw_rad,
  /// scan_time_offset_s, then gyro_scale, gyro_bias_rad_s with a gyro.
  std::vector<std::string> covariance_order;
  std::vector<double> covariance;
  std::string scale_source;           ///< "lidar_ranges" or "distance_m"
  std::vector<ParameterExcitation> excitation;
  bool wheels_determined = true;      ///< false: none of the wheel parameters is determined (exit 3)
  std::vector<std::string> warnings;
  // What the drive was.
  double duration_s = 0.0, straight_m = 0.0, turned_left_rad = 0.0, turned_right_rad = 0.0;
  std::size_t scans = 0, measurements = 0, open_measurements = 0, lost = 0;
  LinearStart linear;                 ///< Censi's linear step (start values), for comparison
  LidarJointFit fit;
};

/// Calibrates. Throws InvalidOptions for bad options; QualityGateError with
/// advice for a drive that cannot be calibrated: too short, a corridor (the
/// direction named), swapped wheels, a wheel running backwards, a fit that
/// gives a non-positive diameter or wheelbase.
LidarCalibration CalibrateLidar(const LidarCalibrationInput& input, const LidarCalibrationOptions& options = {});

}  // namespace umbmark::calibration
