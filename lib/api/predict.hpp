// `umbmark predict` as one library call (lib/api, see calibrate.hpp for the
// pattern): the closed-form mean pose and covariance after a path (Chong &
// Kleeman eqs. 23-28), its second-order heading correction, and optionally
// a Monte Carlo estimate of the same (each segment split into partitions
// with white wheel noise).
//
//   api::PredictOptions o;
//   o.robot.robot_file = "robot.toml";
//   o.k_L = o.k_R = 1e-3;
//   o.path = "line:2,turn:1.5708";
//   const api::PredictResult r = api::Predict(o);   // r.covariance(2, 2)
//   nlohmann::json j = api::ToJson(r);              // == `--json` of the command
//
// Errors: InvalidOptions (Check()'s message, a bad path, a P0 that is no
// covariance, a Monte Carlo too large for the machine), InputError (a bad
// robot file), QualityGateError (a mean or covariance that is not finite).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "api/robot_source.hpp"
#include "core/pose2.hpp"
#include "core/progress.hpp"
#include "error_models/wheel_noise.hpp"

namespace umbmark::api {

/// Every option of `umbmark predict` (the flag in brackets).
struct PredictOptions {
  RobotSource robot;     ///< [--robot, --wheelbase, ...] required
  double k_L = 0.0;      ///< [--kl] left wheel noise constant [m^1/2], >= 0 (required on the command line)
  double k_R = 0.0;      ///< [--kr] right wheel noise constant [m^1/2], >= 0
  std::string path;      ///< [--path] line:D, turn:ANGLE_RAD, arc:L_LEFT:L_RIGHT, comma-separated (required)
  /// [--P0] initial pose covariance: 3 values (variances xx, yy, thth), 6
  /// (xx, xy, xth, yy, yth, thth) or 9 (row-major); empty = zero.
  std::vector<double> P0;
  std::optional<std::int64_t> monte_carlo;  ///< [--monte-carlo] runs, 2 to 2^40; unset = none
  int partitions = 1000;                    ///< [--partitions] per segment, 1 to 2^30
  std::uint64_t seed = 1;                   ///< [--seed] run i uses streams derived from (seed, i)
  int threads = 0;                          ///< [--threads] 0 = all cores
  ProgressCallback progress;                ///< the Monte Carlo's, in runs; empty = none

  /// "" when valid, else a message naming the bad field by its flag.
  std::string Check() const;
};

/// One segment of the path in wheel travel (JSON `segments[i]`).
struct PredictSegment {
  double left_m = 0.0, right_m = 0.0;
  std::string form;  ///< line | turn | arc
};

/// A mean pose and its covariance.
struct PoseEstimate {
  Pose2 mean;
  PoseCovariance covariance = PoseCovariance::Zero();
};

/// The Monte Carlo estimate (JSON `monte_carlo`) with its standard errors.
struct PredictMonteCarlo {
  Pose2 mean;  ///< theta on the closed form's branch
  PoseCovariance covariance = PoseCovariance::Zero();
  Eigen::Vector3d mean_se = Eigen::Vector3d::Zero();
  PoseCovariance covariance_se = PoseCovariance::Zero();  ///< Gaussian (Wishart) approximation
  std::int64_t runs = 0;
  int partitions = 0;
  std::uint64_t seed = 0;
  int threads = 0;
  std::int64_t steps = 0;
  double seconds = 0.0, steps_per_second = 0.0;  ///< timings
  std::string kernel;
};

/// The JSON's keys as members of the same names.
struct PredictResult {
  std::string path;  ///< the path spec, normalised
  double wheelbase_m = 0.0, k_L = 0.0, k_R = 0.0;
  PoseCovariance P0 = PoseCovariance::Zero();
  std::vector<PredictSegment> segments;
  Pose2 mean;  ///< theta wrapped to (-pi, pi]
  double theta_continuous_rad = 0.0;
  PoseCovariance covariance = PoseCovariance::Zero();
  PoseEstimate second_order;  ///< with the heading-squared term (docs/noise-model.md)
  std::optional<PredictMonteCarlo> monte_carlo;
  std::vector<std::string> warnings;  ///< a degenerate request (no motion, no noise, few runs)
};

PredictResult Predict(const PredictOptions& options);
nlohmann::json ToJson(const PredictResult& result);

}  // namespace umbmark::api
