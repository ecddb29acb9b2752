// `umbmark evaluate` as a library call: errors of odometry against ground
// truth along trajectories (any path shape) for the recorded parameters and,
// with a calibration, for its parameters, per run and over all runs.
//   Evaluate(EvaluateOptions) -> EvaluateResult; ToJson(result) is the
//   command's --json document; EvaluatePlotSvg / EvaluateReportHtml
//   (evaluate_report.hpp) its --plot and --report.
// Files: reads the trajectory CSVs, manifests, robot and params files named
// in the options; writes nothing.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/robot_source.hpp"
#include "core/robot.hpp"
#include "core/runs.hpp"
#include "evaluation/trajectory_eval.hpp"
#include "kinematics/diff_drive.hpp"

namespace umbmark::api {

struct EvaluateOptions {
  /// DATA: trajectory CSVs or campaign manifests (at least one; a
  /// manifest's endpoint experiments are skipped).
  std::vector<std::string> inputs;
  /// --robot and the per-field overrides: the parameters the odometry used
  /// (on top of a manifest's [robot]).
  RobotSource robot;
  /// --params: a calibration JSON from `calibrate` ("" = none: the recorded
  /// parameters alone).
  std::string params_file;
  /// --integrator: odometry from ticks, arc (exact, the default) or midpoint.
  Integrator integrator = Integrator::kArc;
  /// Keep the first kEvaluatePlotRuns runs for EvaluatePlotSvg (--plot,
  /// --report). Default false: large files are then evaluated in two parts
  /// at once.
  bool keep_plot_runs = false;

  /// "" when usable, else a message naming the bad field.
  std::string Check() const;
};

/// Runs kept for the plot: every run up to this many (the plot says when
/// there were more).
inline constexpr std::size_t kEvaluatePlotRuns = 200;

/// A run kept for the plot, with the file and recorded parameters it came with.
struct EvaluatePlotRun {
  std::string path;
  RobotParams recorded;
  TrajectoryRun run;
};

/// The recorded parameters' side when a calibration is evaluated too: the
/// JSON's "recorded" object.
struct EvaluateRecorded {
  RobotParams parameters;
  EvaluationSummary summary;  ///< "runs" (summary.runs) and "summary"
};

/// What `evaluate` gives; the members are the JSON's keys.
struct EvaluateResult {
  std::string integrator;              ///< "arc" or "midpoint"
  RobotParams parameters;              ///< the calibration's with --params, else the recorded ones
  EvaluationSummary summary;           ///< with `parameters`: "runs" (summary.runs) and "summary"
  std::optional<EvaluateRecorded> recorded;  ///< with --params: the recorded parameters' errors
  std::vector<std::string> warnings;   ///< degenerate data (evaluation/data_warnings.hpp)

  /// Not in the JSON: the runs kept for the plot (keep_plot_runs) and
  /// the number of runs evaluated.
  std::vector<EvaluatePlotRun> plot_runs;
  /// With --params: the calibration's parameters (as `parameters`).
  std::optional<RobotParams> params;
  /// The recorded parameters' evaluation (`recorded->summary` with
  /// --params, else `summary`).
  const EvaluationSummary& Base() const { return recorded ? recorded->summary : summary; }
};

/// Evaluates every trajectory of the inputs. Throws InputError (a file,
/// with line and column) and InvalidOptions (Check()'s message).
EvaluateResult Evaluate(const EvaluateOptions& options);

/// The command's JSON document (the contract's `evaluate --json`).
nlohmann::json ToJson(const EvaluateResult& result);

}  // namespace umbmark::api
