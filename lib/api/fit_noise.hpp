// `umbmark fit-noise` as a library call: maximum-likelihood k_L, k_R
// (Chong & Kleeman eq. 4) with 95 % profile intervals and a goodness-of-fit
// table, from endpoint CSVs of back-and-forth runs, trajectory CSVs of runs
// of any shape, or campaign manifests; the systematic errors estimated
// jointly, given by a calibration, or none.
//   FitNoise(FitNoiseOptions) -> FitNoiseResult; ToJson(result) is the
//   command's --json document; FitNoisePlotSvg / FitNoiseReportHtml
//   (fit_noise_report.hpp) its --plot and --report; result.ros2->yaml the
//   --ros2 file's text.
// Files: reads the inputs, robot and params files; writes nothing.
#pragma once

#include <array>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/robot_source.hpp"
#include "core/progress.hpp"
#include "error_models/odometry_covariance.hpp"
#include "error_models/wheel_noise_fit.hpp"
#include "error_models/wheel_noise_fit_data.hpp"

namespace umbmark::api {

/// Starts a progress display for one step ("fitting k_L, k_R to 60 runs")
/// and returns the callback the step reports to (apps/progress.hpp).
using ProgressStart = std::function<ProgressCallback(const std::string& what)>;

struct FitNoiseOptions {
  /// DATA: endpoint or trajectory CSVs, or campaign manifests (at least one).
  std::vector<std::string> inputs;
  /// --robot and the per-field overrides (on top of a manifest's [robot]).
  RobotSource robot;
  /// --distance: endpoint data drove D forward, then D back [m] (required
  /// for endpoint CSVs given directly; unset by default).
  std::optional<double> distance_m;
  /// --meas-sigma: the reference's noise per measured pose, {} (default:
  /// the manifest's [ground_truth], else 0), {SXY} or {SXY, STHETA} [m, rad].
  std::vector<double> meas_sigma;
  bool first_order = false;  ///< --first-order: no heading-squared term (default: second order)
  bool ml = false;           ///< --ml: plain maximum likelihood (default: REML)
  /// --params: a `calibrate --json` file whose parameters fix the systematic
  /// errors ("" = none).
  std::string params_file;
  /// --systematic: "estimate" (the default: E_d, E_b jointly with k) or
  /// "none" (a calibrated robot); ignored with params_file.
  std::string systematic = "estimate";
  /// --ros2: the covariance YAML's path, for its messages and the JSON ("" =
  /// none: no result.ros2). The controller named at its top, and the rate
  /// and speed its variances are stated for.
  std::string ros2_file;
  std::string controller = "diff_drive_controller";
  OdometryCovarianceOptions covariance;
  /// Progress of the fit (none by default).
  ProgressStart progress;

  /// "" when usable, else a message naming the bad field.
  std::string Check() const;
};

/// The JSON's "systematic_errors": what the runs' paths were built with.
struct FitNoiseSystematicErrors {
  std::string source;                          ///< "estimated", "params" or "none"
  SystematicErrors used;                       ///< E_b, c_L, c_R (E_d = c_R / c_L)
  std::optional<SystematicEstimate> estimate;  ///< when estimated: E_d_se, E_b_se, *_determined
};

/// The JSON's "ros2": the --ros2 file's covariance and where each k came from.
struct FitNoiseRos2 {
  std::string file, controller;
  double rate_hz = 0.0, speed_mps = 0.0;
  double k_L = 0.0, k_R = 0.0;                        ///< an undetermined k at its 95 % upper bound
  std::string k_L_source, k_R_source;                 ///< "estimate" or "upper95"
  std::array<double, 6> pose_covariance_diagonal{};   ///< x, y, z, roll, pitch, yaw
  std::array<double, 6> twist_covariance_diagonal{};  ///< vx, vy, vz, wx, wy, wz
  std::string yaml;                                   ///< the file's text (not in the JSON)
};

/// What `fit-noise` gives; the members are the JSON's keys. `fit` holds
/// k_L, k_R, their intervals (k_L_ci95 = fit.k_L_ci), runs, groups,
/// goodness_of_fit, the covariances, neg_log_likelihood and
/// likelihood_passes, which the JSON has at its top level.
struct FitNoiseResult {
  WheelNoiseFitSummary fit;
  bool k_L_determined = true, k_R_determined = true;  ///< false: the estimate sits at the boundary 0
  int skipped_runs = 0;                               ///< runs without ground truth at both ends
  std::array<double, 2> meas_sigma{};                 ///< the reference noise used [m, rad]
  bool second_order = true, restricted = true;
  std::vector<std::string> inputs;                    ///< the data files read, in order
  FitNoiseSystematicErrors systematic_errors;
  std::vector<std::string> warnings, notes;
  std::optional<FitNoiseRos2> ros2;                   ///< with ros2_file
};

/// Reads the inputs and fits. Throws InputError (a file, line, column),
/// InvalidOptions (Check()'s message, a missing --distance or wheelbase),
/// QualityGateError when --ros2 would need a k the runs do not bound.
FitNoiseResult FitNoise(const FitNoiseOptions& options);

/// The command's JSON document (the contract's `fit-noise --json`).
nlohmann::json ToJson(const FitNoiseResult& result);

}  // namespace umbmark::api
