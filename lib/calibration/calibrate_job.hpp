// One `calibrate` job: classic UMBmark on one set of square runs, plus (for
// trajectory input) the evaluation measures before and after the correction
// and the 3*SEM rule applied to the corrected runs.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "calibration/refine.hpp"
#include "calibration/umbmark.hpp"
#include "core/progress.hpp"
#include "core/runs.hpp"
#include "evaluation/return_error.hpp"
#include "evaluation/trajectory_eval.hpp"

namespace umbmark {

/// The runs of one calibration, already loaded.
struct CalibrateInput {
  std::string label;   ///< what the user called it (file, or file#experiment)
  std::string path;    ///< data file, for messages
  RobotParams recorded;
  double side_m = 0.0;
  std::vector<ReturnError> errors;           ///< from endpoints, or computed from trajectories
  std::optional<TrajectoryData> trajectories;  ///< trajectory input only
  std::vector<std::string> files;              ///< the data files behind it (several when pooled)
  /// Recording session of each run (same order as errors): the part index
  /// when PoolInputs pooled several square experiments (each experiment of
  /// a manifest is one recording session). Empty: one session.
  std::vector<int> sessions;
  /// Paths of other shapes (a manifest's circles, free paths, back-and-forth
  /// runs) with ground truth: never used to calibrate, only to compare the
  /// methods on paths they did not see (heldout.hpp).
  std::vector<TrajectoryData> unseen;
};

struct CalibrateJobOptions {
  /// side_m is taken from the input; the other fields as documented there.
  UmbmarkOptions umbmark;
  /// Integrator for odometry from ticks (trajectory input). Default kArc.
  Integrator integrator = Integrator::kArc;
  /// When set, also run the refined (Ceres) calibration on the runs UMBmark
  /// used, started from the classic solution; its integrator and start are
  /// overwritten from the fields above and the UMBmark result.
  std::optional<RefineOptions> refine;
  /// A failed refined fit: false (default) throws RefineError; true keeps
  /// the classic result and records the failure in `refine_failure`.
  bool keep_classic_on_refine_failure = false;
  /// Settings of the full-path fits (refined, with the trajectory settings
  /// the user chose) that the held-out comparison computes on trajectory
  /// input when `refine` is not set: every method the data allow is
  /// compared, --refine only adds intervals and identifiability. Default
  /// RefineOptions{}.
  RefineOptions compare_refine;
  /// Progress of the held-out comparison (heldout.hpp), in folds
  /// (core/progress.hpp). Default: none.
  ProgressCallback progress;
};

/// What the corrected parameters do on the same runs (trajectory input).
struct AfterCorrection {
  EvaluationSummary before, after;
  ClusterStats cw, ccw;       ///< return-error clusters with the corrected parameters
  double E_max_syst_m = 0.0;  ///< eq. 3.4 after correction
  double sem_m = 0.0;
  /// E_max,syst after > 3*SEM: a second compensation pass is indicated.
  bool second_pass_worthwhile = false;
};

struct CalibrateJobResult {
  std::string label, path;
  UmbmarkSummary umbmark;
  std::optional<AfterCorrection> evaluation;
  std::optional<RefineSummary> refined;
  /// Evaluation measures with the refined parameters (trajectory input).
  std::optional<EvaluationSummary> refined_evaluation;
  /// Set when the refined fit failed and keep_classic_on_refine_failure.
  std::optional<RefineError> refine_failure;
};

/// Builds the input from trajectories: return errors with the recorded
/// parameters, and a check that every run's cw/ccw label agrees with the
/// sign of its ground-truth total rotation. Throws InputError otherwise.
/// The runs are kept in the input (pass them with std::move to avoid a copy).
CalibrateInput InputFromTrajectories(TrajectoryData data, const RobotParams& recorded, double side_m,
                                     Integrator integrator, const std::string& label);
CalibrateInput InputFromEndpoints(const EndpointData& data, const RobotParams& recorded, double side_m,
                                  const std::string& label);

/// Centre of gravity of the return errors of `direction` (cw | ccw) whose
/// run UMBmark used (flags in the same order as errors).
ClusterStats ClusterOfUsed(const std::vector<ReturnError>& errors, const std::vector<RunFlag>& flags,
                           const std::string& direction);

/// The refined fit on the runs of `input` where keep[i] (same order as
/// input.errors), started from `start` (the classic estimate), odometry with
/// `integrator`: trajectories when the input has them, else return errors.
/// Throws RefineError (exit 3) when the fit fails its quality gates.
RefineSummary RefineInput(const CalibrateInput& input, const std::vector<bool>& keep, RefineOptions options,
                          const UmbmarkEstimate& start, Integrator integrator);

/// True when some run has ground truth between its first and last sample.
/// Without it, the refined fit of trajectory input uses the return errors
/// (commanded-square model, as for endpoint input): the path carries no
/// further information.
bool HasInteriorGroundTruth(const TrajectoryData& data);

/// Pools the square experiments of one campaign into one calibration: the
/// return errors (and trajectories, when every part has them) of all parts.
/// UMBmark's eqs. 4.20-4.24 take one side length, so the parts must share
/// side_m and the recorded robot (InputError otherwise). Run ids become
/// "<tag>:<run>" (tags[i] names part i, e.g. its experiment number) so runs
/// of different files stay apart.
CalibrateInput PoolInputs(const std::vector<CalibrateInput>& parts, const std::vector<std::string>& tags,
                          const std::string& label);

/// Runs UMBmark (and the after-correction evaluation when trajectories are
/// present, and the refined fit when asked). Throws RefineError (exit 3)
/// when the refined fit fails its quality gates.
CalibrateJobResult RunCalibrateJob(const CalibrateInput& input, const CalibrateJobOptions& options);

}  // namespace umbmark
