// `umbmark plan` as library calls: the runs to drive for a target precision
// (Plan), and what a recorded campaign determines (PlanCheck, `plan --check`).
//   Plan(PlanOptions) -> PlanResult; ToJson(result) is `plan --json`;
//   PlanMotionsJson / WritePlanMotions give `--motions`.
//   PlanCheck(PlanCheckOptions) -> PlanCheckResult; ToJson(result) is
//   `plan --check --json`.
// Files: reads the robot file, the fit-noise JSON and (PlanCheck) the
// manifest and its data files; WritePlanMotions writes one file atomically.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/robot_source.hpp"
#include "planning/check.hpp"
#include "planning/plan.hpp"

namespace umbmark::api {

/// The wheel noise a plan assumes: --kl/--kr or a `fit-noise --json` file.
struct PlanNoise {
  /// [--kl, --kr] k_L, k_R [m^1/2]; unset = not given.
  std::optional<double> k_L, k_R;
  /// [--noise] k_L, k_R from a `fit-noise --json` file ("" = none; not
  /// together with k_L/k_R).
  std::string noise_file;
};

/// Driving speeds and the logging rate (defaults as the command line's).
struct PlanTiming {
  double speed_m_s = 0.3;        ///< --speed
  double turn_rate_rad_s = 1.0;  ///< --turn-rate
  double pause_s = 1.0;          ///< --pause between motions
  double rate_hz = 20.0;         ///< --rate of the recording
};

struct PlanOptions {
  /// --robot and the per-field overrides (required: a file or all three).
  RobotSource robot;
  /// The wheel noise (required: k_L and k_R, or noise_file).
  PlanNoise noise;
  /// --ground-truth: "mocap" (along the path, default), "scan" or "tape".
  std::string ground_truth = "mocap";
  /// --gt-sigma-xy [m], --gt-sigma-theta [rad]; unset = by kind.
  std::optional<double> gt_sigma_xy_m, gt_sigma_theta_rad;
  /// --target-E_d, --target-E_b, --target-scale, --target-k: 95 % half-widths
  /// wanted (at least one; planning::PlanOptions::Check()).
  std::optional<double> target_E_d, target_E_b, target_scale, target_k;
  double max_side_m = 3.0;          ///< --max-side [m]
  std::optional<double> max_time_s;  ///< --max-time [s]; unset = no limit
  PlanTiming timing;

  /// "" when usable, else a message naming the bad field (the robot file and
  /// noise file are read by Plan).
  std::string Check() const;
};

/// The ground truth a result assumed.
struct PlanGroundTruth {
  std::string kind;  ///< mocap | scan | tape
  double sigma_xy_m = 0.0, sigma_theta_rad = 0.0;
};

/// What `plan` gives; the members are the JSON's keys.
struct PlanResult {
  planning::PlanDesign design;
  /// Targeted quantities (E_d, E_b, scale, k_L, k_R): predicted 95 %
  /// half-width (null: undetermined).
  std::map<std::string, std::optional<double>> predicted_ci95;
  std::map<std::string, double> targets;
  /// Quantities not targeted whose half-width is known anyway.
  std::map<std::string, double> also_predicted_ci95;
  std::string binding;  ///< the quantity that decides the number of runs
  std::string method;   ///< what calibrate would recommend on it
  PlanGroundTruth ground_truth;
  double k_L = 0.0, k_R = 0.0;
  std::vector<std::string> notes;
  std::vector<std::string> warnings;

  /// Not in the JSON: the library's options and result (for the text and
  /// the motions).
  planning::PlanOptions options;
  planning::PlanResult plan;
};

/// Plans the campaign. Throws InvalidOptions (Check()'s message, or
/// planning's), InputError (robot or noise file), QualityGateError when the
/// targets cannot be met within the limits.
PlanResult Plan(const PlanOptions& options);

/// The command's JSON document (the contract's `plan --json`).
nlohmann::json ToJson(const PlanResult& result);

/// `--motions`: the design as a list of motions a robot script can drive
/// (text of the JSON array, newline-terminated).
std::string PlanMotionsJson(const PlanResult& result);
/// Writes PlanMotionsJson(result) to `path` atomically (InputError on failure).
void WritePlanMotions(const PlanResult& result, const std::string& path);

struct PlanCheckOptions {
  /// --check: the campaign manifest (.toml) to examine. Required.
  std::string manifest;
  /// Overrides of the manifest's [robot].
  RobotSource robot;
  /// Optional wheel noise (k_L and k_R together, or noise_file); none =
  /// fitted to the runs.
  PlanNoise noise;
  /// --gt-sigma-xy [m], --gt-sigma-theta [rad]: override the manifest's
  /// [ground_truth].
  std::optional<double> gt_sigma_xy_m, gt_sigma_theta_rad;
  PlanTiming timing;

  /// "" when usable, else a message naming the bad field.
  std::string Check() const;
};

/// A group of parameters or effects the campaign cannot tell apart.
struct PlanConfusion {
  std::vector<std::string> what;
  std::string kind;  ///< planning::Confusion::kind
  std::string add;
  double correlation = 1.0;
};

/// What `plan --check` gives; the members are the JSON's keys.
struct PlanCheckResult {
  std::string input;  ///< the manifest
  std::map<std::string, double> predicted_ci95;  ///< every quantity determined
  std::vector<PlanConfusion> cannot_separate;
  std::string method;
  double k_L = 0.0, k_R = 0.0;
  bool noise_fitted = false;
  /// The wheel noise the calibration's prediction uses ("calibration_noise":
  /// k_L, k_R; planning::CheckResult::calibration_noise).
  WheelNoise calibration_noise;
  planning::GroundTruthModel ground_truth;  ///< "ground_truth": along_path, sigma_xy_m, sigma_theta_rad
  int square_runs_cw = 0, square_runs_ccw = 0, other_runs = 0;
  std::vector<std::string> notes;
  std::vector<std::string> warnings;

  /// Not in the JSON: the library's result (for the text).
  planning::CheckResult check;
};

/// Examines the recorded campaign. Throws InvalidOptions, InputError.
PlanCheckResult PlanCheck(const PlanCheckOptions& options);

/// The command's JSON document (`plan --check --json`).
nlohmann::json ToJson(const PlanCheckResult& result);

/// (name, predicted 95 % half-width, target) of the five quantities a plan
/// can target: E_d, E_b, scale, k_L, k_R (the k target applies to both).
std::vector<std::tuple<const char*, std::optional<double>, std::optional<double>>> PlanQuantities(
    const planning::HalfWidths& h, const planning::PlanOptions& o);

}  // namespace umbmark::api
