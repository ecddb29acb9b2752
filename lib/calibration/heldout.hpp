// Which calibration to put on the robot: the prediction error of every
// calibration method the data allow on runs it did not see (calibrate's
// `recommended` and per-method `heldout_error`).
//
// What is held out, in order of preference (scheme):
//  - "unseen_paths": the input carries paths of other shapes (a manifest's
//    circles, free paths, back-and-forth runs: CalibrateInput::unseen).
//    Every method calibrates on all used square runs and predicts each
//    unseen run: its final position error, odometry from the run's first
//    ground-truth pose (the OptiOdom protocol). One fold per unseen run.
//  - "leave_one_session_out": square runs of two or more recording sessions
//    (CalibrateInput::sessions). Every method calibrates on the other
//    sessions and predicts each run of the left-out one; one fold per run.
//  - "leave_one_run_out" (or "k_fold_over_runs" above 200 used runs: 10
//    interleaved groups, a fold's error is its runs' mean): one session of
//    squares. In-distribution: it does not see other shapes or days, which
//    is why the recommendation below prefers the simpler method unless the
//    difference is clear.
// Measures: unseen paths, the final position error; square trajectories,
// the largest position error along the left-out run (a closed square's
// final pose hides errors that cancel); return errors only (endpoint
// input), the distance between the measured return error (x, y) and the
// exact commanded-square return error of a robot with those parameters.
// Outlier rejection and --exclude-runs are decided once on all runs.
//
// Methods, simplest first: recorded (no calibration); umbmark_x, umbmark_y,
// umbmark_mean (classic, the overall scale held); plain_least_squares
// (PlainLeastSquaresOptions: wheelbase and both diameters, no modelling
// choice) and refined, on trajectory input with ground truth along the path
// (with or without --refine), refined also on return errors with --refine.
//
// Recommendation (never empty unless skipped):
//  - the baseline is the simplest well-determined calibration:
//    plain_least_squares where the path determines all three parameters;
//    if it is not well determined, the refined full-path fit (it measures
//    the overall scale too); else the classic estimator asked for
//    (umbmark_<estimator>). A method whose fit failed on some fold is not
//    well determined and not recommendable;
//  - a method that holds the overall scale at the recorded value (recorded,
//    classic UMBmark, the refined fit of return errors) is never
//    recommended over a baseline that measures it unless the held-out runs
//    are of other shapes (unseen_paths): squares close on themselves
//    whatever the scale, so a comparison on squares cannot see what the
//    held scale costs on circles and free paths (on the OptiOdom sessions
//    the classic rows lose up to 5.6 mm per pair,
//    docs/calibration-comparison.md);
//  - with a full-path baseline and runs of ONE session and shape
//    (leave_one_run_out, k_fold_over_runs) the baseline is kept: the
//    comparison is in-distribution and no evidence that another method
//    predicts other days or shapes better (the refined fit's margin on such
//    folds did not carry over to other nights);
//  - otherwise another method at least as complete as the baseline is
//    recommended only when it beats the baseline by more than the standard
//    error of the paired difference; the lowest such;
//  - `recorded` is recommended when its mean is the lowest (and it is
//    eligible, above);
//  - with fewer than 3 folds the baseline (a note says why).
// `checked` and `not_checked` say in words what the held-out runs could
// and could not test (shapes, sessions, the overall scale).
// The recommended method's mean and SE are the expected error on unseen
// paths (expected_error_m, expected_error_sem_m).
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "calibration/calibrate_job.hpp"

namespace umbmark {

struct MethodHeldout {
  std::string method;
  RobotParams parameters;  ///< calibrated on all used runs
  /// Prediction error of each fold [m] (NaN where the method failed).
  std::vector<double> fold_errors_m;
  double mean_m = 0.0;  ///< over the folds every method completed
  double sem_m = 0.0;   ///< standard error of that mean
  double rms_m = 0.0;
  int folds = 0;         ///< folds in the mean
  int failed_folds = 0;  ///< folds where this method's fit failed (not recommendable)
  std::string failure;   ///< the first failure's message
  /// 0 recorded, 1 classic UMBmark, 2 plain least squares, 3 refined.
  int simplicity = 0;
  /// The method measures the overall scale (mean wheel diameter): the
  /// full-path fits with the scale not held. The others keep it at the
  /// recorded value.
  bool fits_scale = false;
  bool fitted_all = true;  ///< its fit on all used runs succeeded
  bool Recommendable() const { return fitted_all && failed_folds == 0 && folds > 0 && std::isfinite(mean_m); }
};

struct HeldoutComparison {
  /// leave_one_run_out | k_fold_over_runs | leave_one_session_out | unseen_paths
  std::string scheme = "leave_one_run_out";
  /// final_position_error_m (unseen paths) | max_position_error_m (square
  /// trajectories) | return_error_prediction_m (endpoints)
  std::string measure;
  std::vector<std::string> left_out;  ///< run ids (or fold names), fold order
  int sessions = 1;                   ///< recording sessions of the square runs
  std::vector<MethodHeldout> methods;
  /// The simplest well-determined calibration (see above).
  std::string baseline;
  /// See above; empty only when no method could be fitted at all.
  std::string recommended;
  /// Why `recommended` (one sentence for the user).
  std::string why;
  /// Expected error on unseen paths of the recommended method: its mean
  /// held-out error and that mean's standard error [m] (NaN without folds).
  double expected_error_m = 0.0, expected_error_sem_m = 0.0;
  /// The runner-up (the lowest other recommendable method, recorded
  /// included) and its paired difference to the recommended method:
  /// runner-up minus recommended [m] and that mean's standard error (0
  /// without a runner-up). Negative when the recommended method was kept as
  /// the simpler one although the runner-up's mean is lower.
  double runner_up_difference_m = 0.0, runner_up_difference_sem_m = 0.0;
  std::string runner_up;
  /// What the held-out runs could test, and what they could not (one
  /// sentence each, for the text and JSON `heldout.checked`,
  /// `heldout.not_checked`).
  std::vector<std::string> checked, not_checked;
  std::vector<std::string> notes;

  const MethodHeldout* Find(const std::string& method) const;
};

/// Does the model explain the return errors' centres of gravity within
/// their scatter? Per direction with n >= 4 runs: Hotelling's
/// T^2 = n d' S^-1 d (d = mean measured minus model return error in x, y, S
/// the runs' sample covariance), exact under normal scatter as
/// F(2, n - 2) after scaling; each group's p-value is mapped to its
/// chi-square(2) equivalent and summed, with 2 G - 2 degrees of freedom (two
/// factors, E_b and E_d, fitted to the G centres).
struct ModelCheck {
  bool available = false;
  double reduced_chi2 = 0.0;
  int dof = 0;
  double p_value = 1.0;  ///< of a misfit at least this large under the model
};
ModelCheck CheckCentresAgainstModel(const CalibrateInput& input, const std::vector<RunFlag>& flags,
                                    const RobotParams& parameters, bool final_turn = true);

/// Warnings for a person deciding what to trust (calibrate's `warnings`):
/// fewer than 4 runs in a direction, a model check with p < 0.01, no
/// calibration predicting held-out runs better than the recorded parameters.
std::vector<std::string> TrustWarnings(const CalibrateJobResult& result, const HeldoutComparison& heldout,
                                       const ModelCheck& check);

/// The recommendation rule alone (above) on methods whose fold errors are
/// filled (NaN where a method failed; every method the same folds,
/// `recorded` among them) and `out->scheme`, `sessions` set: computes each
/// method's mean, SE and rms over the folds every method completed, then
/// baseline, recommended, why, the expected error, the runner-up, checked,
/// not_checked and notes. Throws InvalidOptions for inconsistent folds.
void RecommendFromFolds(const CalibrateJobOptions& options, HeldoutComparison* out);

/// Runs the comparison for `input`, given the job's options and its result
/// on all runs (`full`). Never throws for a failing fold (recorded in the
/// method's failed_folds); throws InvalidOptions for bad options only.
HeldoutComparison CompareMethodsHeldout(const CalibrateInput& input, const CalibrateJobOptions& options,
                                        const CalibrateJobResult& full);

}  // namespace umbmark
