// Which calibration to put on the robot: leave-one-run-out prediction error
// of every calibration method the data allow (calibrate's `recommended` and
// per-method `heldout_error`).
//
// Each run the calibration used is left out in turn; every method calibrates
// on the remaining runs and its parameters predict the left-out run:
//  - trajectory input: the largest position error along the left-out run
//    with those parameters (odometry from its encoder samples against its
//    ground truth, as `evaluate` computes it). The whole path, not the final
//    pose: a closed square's final pose hides errors that cancel (on the June
//    OptiOdom squares the final pose favoured classic UMBmark where the
//    whole path and other paths favour the refined fit);
//  - return errors only (endpoint input): the distance between the measured
//    return error (x, y) and the exact commanded-square return error of a
//    robot with those parameters (model/commanded_square.hpp).
// Above 200 used runs (where one calibration per run would cost time
// quadratic in the runs) the folds are 10 interleaved groups of runs
// instead (scheme "k_fold_over_runs"; a fold's error is its runs' mean).
// Outlier rejection and --exclude-runs are decided once on all runs and kept
// across folds. Methods: recorded (no calibration, the baseline),
// umbmark_x, umbmark_y, umbmark_mean (classic estimators), refined and, for
// trajectories, plain_least_squares (PlainLeastSquaresOptions) when the
// refined fit is asked for.
#pragma once

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
};

struct HeldoutComparison {
  std::string scheme = "leave_one_run_out";  ///< or "k_fold_over_runs" (above 200 runs)
  /// max_position_error_m (trajectories) | return_error_prediction_m (endpoints)
  std::string measure;
  std::vector<std::string> left_out;  ///< run ids, fold order
  std::vector<MethodHeldout> methods;
  /// Lowest mean among calibration methods without failed folds; empty when
  /// fewer than 3 folds could be formed.
  std::string recommended;
  /// Standard error of the paired difference between the recommended method
  /// and the runner-up [m] (0 without a runner-up).
  double runner_up_difference_m = 0.0, runner_up_difference_sem_m = 0.0;
  std::string runner_up;
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

/// Runs the comparison for `input`, given the job's options and its result
/// on all runs (`full`). Never throws for a failing fold (recorded in the
/// method's failed_folds); throws InvalidOptions for bad options only.
HeldoutComparison CompareMethodsHeldout(const CalibrateInput& input, const CalibrateJobOptions& options,
                                        const CalibrateJobResult& full);

}  // namespace umbmark
