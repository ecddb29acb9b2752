// `umbmark calibrate` as one library call (lib/api: one header per command,
// <Command>Options -> <Command>() -> <Command>Result, ToJson()): classic
// UMBmark (Borenstein & Feng) from CW/CCW square runs in endpoint or
// trajectory CSV, campaign manifests or data in memory; the refined fit
// (--refine), the held-out comparison of the methods and its
// recommendation, and the files the command writes (--ros2, --plot,
// --report). apps/cmd_calibrate.cpp parses the flags into CalibrateOptions,
// calls Calibrate() and prints; the Python module calls the same.
//
//   api::CalibrateOptions o;
//   o.inputs = {"campaign.toml"};
//   o.refine = true;
//   const api::CalibrateResult r = api::Calibrate(o);
//   const double E_d = r.results[0].result->E_d;
//   std::string text = api::DumpJson(api::ToJson(r));  // == `--json` of the command
//
// Errors: InvalidOptions (a bad option: Check()'s message), InputError (bad
// data, naming file and line), QualityGateError (an implausible result; a
// refined fit that failed is RefineError, a QualityGateError). With one
// calibration they are thrown; in a batch (several inputs or units) each
// failing unit is recorded in the result and the others go on.
#pragma once

#include <functional>
#include <optional>
#include <variant>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/robot_source.hpp"
#include "calibration/calibrate_job.hpp"
#include "calibration/heldout.hpp"
#include "core/progress.hpp"
#include "planning/advice.hpp"
#include "core/runs.hpp"

namespace umbmark::io {
class OutputSet;
}

namespace umbmark::api {

/// Runs already in memory (e.g. numpy arrays), calibrated as a CSV of
/// them would be; `name` stands where a file's path would (messages, JSON
/// `input`).
struct CalibrateData {
  std::string name = "<runs>";
  std::variant<EndpointData, TrajectoryData> runs;
};

/// Every option of `umbmark calibrate` (the flag in brackets), with the
/// command line's defaults.
struct CalibrateOptions {
  /// [DATA] endpoint or trajectory CSV files or campaign manifests (.toml).
  std::vector<std::string> inputs;
  /// Data in memory, calibrated after `inputs` as further inputs (CSV-like:
  /// they need side_m and the robot).
  std::vector<CalibrateData> data;
  /// [--robot, --wheelbase, ...] required for CSV and in-memory input; a
  /// manifest's [robot] otherwise, overridden field by field.
  RobotSource robot;
  /// [--side] square side [m]; required for CSV and in-memory input, else
  /// overrides the manifest's. Plausible range 0.05 to 100 m.
  std::optional<double> side_m;
  std::string estimator = "mean";          ///< [--estimator] x | y | mean
  std::string integrator = "arc";          ///< [--integrator] arc | midpoint (odometry from ticks)
  std::string ed_wheelbase = "corrected";  ///< [--ed-wheelbase] corrected | recorded (eq. 4.22)
  std::vector<std::string> exclude_runs;   ///< [--exclude-runs] run ids to leave out
  bool reject_outliers = false;            ///< [--reject-outliers] drop runs flagged as outliers
  double outlier_threshold = 3.5;          ///< [--outlier-threshold] robust score above which a run is flagged, > 0
  bool refine = false;                     ///< [--refine] add the exact Ceres fit
  std::vector<std::string> fix;            ///< [--fix] with refine: "scale" held at the recorded value
  std::vector<std::string> free;           ///< [--free] with refine: "scale" estimated
  std::string loss = "huber";              ///< [--loss] huber | cauchy | none
  double loss_scale_m = 0.02;              ///< [--loss-scale] robust loss scale [m], > 0
  int samples_per_run = 100;               ///< [--samples-per-run] poses per trajectory run, 2 to 100000
  std::string sampling = "per_run";        ///< [--sampling] per_run | every_sample
  /// [--start-pose] first_sample | standstill_mean | fitted | session_frame
  std::string start_pose = "first_sample";
  double heading_weight = 1.0;             ///< [--heading-weight] wheelbases per radian, >= 0
  /// [--use] the calibration --ros2, --plot and --report show:
  /// recommended (held-out comparison; classic when skipped) | classic |
  /// refined (needs refine).
  std::string use = "recommended";
  bool per_experiment = false;  ///< [--per-experiment] one calibration per square experiment of a manifest
  bool no_heldout = false;      ///< [--no-heldout] skip the held-out comparison
  /// [--scan-range-scale] a lidar's range scale (scan ground truth), 0.5 to 2.
  std::optional<double> scan_range_scale;
  /// [--ros2] write a ros2_control diff_drive_controller parameter file of
  /// the `use` calibration ("" = none; tagged per unit in a batch).
  std::string ros2;
  std::string controller = "diff_drive_controller";  ///< [--controller] name at the top of the ros2 file
  std::string plot;    ///< [--plot] SVG of the return errors and paths ("" = none)
  std::string report;  ///< [--report] self-contained HTML report ("" = none)

  /// Progress of the whole command, in inputs (core/progress.hpp). Empty: none.
  ProgressCallback progress;
  /// The output set the files are registered with and written through
  /// (output/output_set.hpp): the command line passes its own, holding
  /// --json too. Null: Calibrate() makes its own.
  io::OutputSet* outputs = nullptr;

  /// "" when valid, else a message naming the bad field by its flag, its
  /// value and the rule (as the command line says it).
  std::string Check() const;
};

/// One run of a calibration (JSON `runs[i]`).
struct CalibratedRun {
  std::string run, direction;
  double ex_m = 0.0, ey_m = 0.0;
  std::optional<double> etheta_rad;     ///< null for endpoint data without a heading
  std::optional<double> outlier_score;  ///< null with too few runs
  bool outlier = false, excluded = false, rejected = false;
};

/// The parameters the outputs use (JSON `outputs_use`), and the ros2
/// multipliers (wheel separation, left, right radius) relative to the
/// recorded robot.
struct OutputsUse {
  std::string method;  ///< umbmark_<estimator> | refined | plain_least_squares | recorded
  RobotParams parameters;
  std::string why;
  /// "kept" (the recorded mean wheel diameter), "ground_truth" (fitted to
  /// the ground truth's distances), "range_scale" (a lidar's distances
  /// corrected by scan_range_scale).
  std::string scale_source = "ground_truth";
  std::string scale_note;  ///< for the ros2 file's comment ("" = fitted scale)
  double separation = 1.0, left = 1.0, right = 1.0;
};

/// One calibration (one input, or one square experiment with
/// per_experiment): the JSON's keys as members of the same names; `job` has
/// the computation's details the nested keys come from.
struct CalibrateUnitResult {
  std::string input;     ///< the input's label (file, file#experiment, pooled)
  std::string robot_id;  ///< "" = none (the JSON then has no robot_id)
  std::string method = "umbmark";
  std::string estimator;  ///< x | y | mean
  double side_m = 0.0;
  std::string integrator;
  double E_d = 1.0, E_b = 1.0, alpha_rad = 0.0, beta_rad = 0.0, R_m = 0.0, c_L = 1.0, c_R = 1.0;
  double E_max_syst_m = 0.0, sem_m = 0.0, three_sem_m = 0.0;
  bool compensation_worthwhile = false;
  RobotParams parameters;           ///< the classic UMBmark correction
  RobotParams recorded_parameters;  ///< what the runs were recorded with
  std::vector<CalibratedRun> runs;
  std::vector<std::string> experiments;  ///< the data files behind it
  std::optional<std::string> refine_error;  ///< the refined fit failed; the classic result stands (exit 3)
  /// JSON `heldout`, `heldout_error` (methods) and `recommended`; scheme
  /// "skipped" with no_heldout.
  HeldoutComparison heldout;
  ModelCheck model_check;  ///< JSON null when not available
  OutputsUse outputs_use;
  std::vector<std::string> warnings;
  /// plan --check's analysis of the unit's square runs (JSON
  /// `design_advice`): the parameters they confuse and the runs that would
  /// determine outputs_use's correction; its sentences are in `warnings`.
  planning::DesignAdvice design_advice;
  /// UMBmark's summary (estimates, centres_of_gravity), the evaluation
  /// before/after (trajectories), the refined fit and its evaluation.
  CalibrateJobResult job;
};

/// What happened to one unit of a batch: its result, or why it failed.
struct CalibrateOutcome {
  enum class Failure { kNone, kInput, kQualityGate, kRefine };
  std::string input;                          ///< label (or the input path when it could not be read)
  std::optional<CalibrateUnitResult> result;  ///< set when it calibrated
  Failure failure = Failure::kNone;
  std::string error;      ///< the failure's message (JSON `error`)
  std::string solver;     ///< kRefine: the solver's report (RefineReport)
  int exit_status = 0;    ///< 1 bad input, 3 quality gate; 3 also for a refine_error
  /// The message the command line prints on stderr for a failure, as the
  /// Python module raises it: kInput the error itself, kQualityGate
  /// "umbmark: quality gate failed: ...", kRefine "LABEL: refined
  /// calibration failed: ..." and the solver's report.
  std::string Message() const;
};

struct CalibrateResult {
  /// One entry per calibration unit, in input order (JSON `results`).
  std::vector<CalibrateOutcome> results;
  /// Several inputs or units: the JSON is {results, failed, warnings};
  /// else it is the one unit's object.
  bool batch = false;
  bool failed = false;                ///< a unit failed, or a refined fit did (JSON `failed`)
  std::vector<std::string> warnings;  ///< every unit's, "LABEL: " first in a batch
  std::vector<std::string> written;   ///< files written, "PATH (what)"
  int exit_status = 0;                ///< the worst of the units' (0, 1, 3)
};

/// Runs the command. Called back after each unit with its outcome (the
/// command line prints as the batch goes); with one calibration a failure
/// is thrown, after the callback only for a failed refined fit (whose
/// solver report the command line prints first). Pass std::move(options)
/// to hand in-memory data over without a copy.
CalibrateResult Calibrate(CalibrateOptions options,
                          const std::function<void(const CalibrateOutcome&)>& on_unit = nullptr);

/// The JSON `umbmark calibrate --json` writes: the unit's object, or for a
/// batch {results, failed, warnings}.
nlohmann::json ToJson(const CalibrateResult& result);
/// One unit's object (docs/formats.md: E_d, E_b, parameters, refined, ...).
nlohmann::json ToJson(const CalibrateUnitResult& unit);

/// The ros2_control diff_drive_controller parameter file of the unit's
/// `outputs_use` (--ros2).
std::string Ros2Parameters(const CalibrateUnitResult& unit, const std::string& controller);
/// The --report page of a unit: headline, next steps, the numbers, the
/// held-out comparison and `plot_svg`.
std::string CalibrationReportHtml(const CalibrateUnitResult& unit, const std::string& plot_svg);

}  // namespace umbmark::api
