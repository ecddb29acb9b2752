// Turns the contract's data files into fit-noise runs (wheel_noise_fit.hpp):
//  - endpoint CSV + the commanded path of every run (e.g. D forward then D
//    back, `--distance D`): the covariance basis from the closed forms
//    along that path;
//  - trajectory CSV: the path from the ticks (ComputeWheelTravel), the
//    covariance basis from Kelly's transition-matrix form along it, and the
//    return error from ground truth at the first and last sample
//    (e = GT_end in the GT_start frame - odometry end, contract eq. 3.1).
// Runs are grouped as `group_prefix + direction`; each group gets its own
// systematic mean in the fit. Trajectory runs labelled neither cw nor ccw
// that turn by more than 1 rad get ":cw" or ":ccw" by the sign of their
// odometry's total rotation (opposite directions, opposite means).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/robot.hpp"
#include "core/runs.hpp"
#include "error_models/wheel_noise_fit.hpp"
#include "error_models/path_spec.hpp"

namespace umbmark {

/// Systematic errors of the true robot relative to the recorded parameters
/// (Borenstein & Feng's E_b and the per-wheel diameter factors c = D_true /
/// D_recorded, which hold E_d = c_R / c_L and the scale).
struct SystematicErrors {
  double E_b = 1.0;
  double c_L = 1.0, c_R = 1.0;
};

struct NoiseFitInputOptions {
  /// The reference's noise per measured pose (start and end each) [m, rad].
  double sigma_xy_m = 0.0;
  double sigma_theta_rad = 0.0;
  /// Include the second-order heading term (second_order.hpp).
  bool second_order = true;
  /// The robot's systematic errors: the motion covariance is propagated
  /// along the path the TRUE robot drove (wheel travel c times what the
  /// odometry measured, wheelbase E_b b), not the odometry's path. An
  /// uncorrected E_d or E_b bends the true path away from the odometry's and
  /// rotates the covariance (on a 10 m back-and-forth, E_b = 1.03 turns the
  /// way back by 5 deg): ignoring it biases k. Default: none (calibrated).
  SystematicErrors systematic;
};

/// Systematic errors from the fitted systematic means of the groups
/// (summary.group_means, summary.predicted_run_covariance): weighted least
/// squares of each group's mean return error against the noise-free return
/// error its runs' odometry travel predicts for a robot with errors
/// (E_b, c_L, c_R) (exact arc integration), weights the inverse covariance of
/// the group mean, a weak prior (sigma 0.05) towards 1 keeping directions the
/// groups do not see (e.g. the scale on a closed path) at 1. Runs without
/// odometry_travel are ignored; no such run: returns the identity.
SystematicErrors EstimateSystematicErrors(const std::vector<WheelNoiseFitRun>& runs,
                                          const WheelNoiseFitSummary& fit);

/// Systematic errors with what the data say about them.
struct SystematicEstimate {
  SystematicErrors value;
  /// Standard error of E_d (joint fit: the scatter's Fisher information,
  /// with the prior) and of E_b (from the group means and the prior).
  double E_d_se = 0.0, E_b_se = 0.0;
  /// Standard error of E_d from the runs' mean return errors alone (with
  /// the weak prior): what the joint fit's prior on E_d is.
  double E_d_se_means = 0.0;
  /// false: the groups' means do not show E_b (no turn in the design, e.g.
  /// straight forward and back): E_b stays at the prior's 1 and k is
  /// relative to the recorded wheelbase (give the calibration to fix it).
  bool E_b_determined = true;
  /// Some run's odometry heading sweeps more than kTurnRad (a turn): when
  /// E_b is not determined although the design turns, the runs are too few
  /// or too noisy for their means to show it (not a design without turns).
  bool turns = false;
  /// false: the scatter pulled E_d further than kMaxJointEdShift from the
  /// means' value (the model does not fit the scatter, or the design says
  /// nothing about E_d); the fit then keeps the means' E_d.
  bool E_d_determined = true;
};

/// Heading sweep [rad] of a run's odometry that counts as a turn
/// (SystematicEstimate::turns).
inline constexpr double kTurnRad = 0.5;

/// Largest shift of E_d the scatter may make from the value the group means
/// give (an uncalibrated robot's E_d is within a few percent of 1).
inline constexpr double kMaxJointEdShift = 0.05;

/// EstimateSystematicErrors with the standard error of E_b.
SystematicEstimate EstimateSystematicErrorsWithSe(const std::vector<WheelNoiseFitRun>& runs,
                                                  const WheelNoiseFitSummary& fit);

/// k_L, k_R with the systematic errors estimated jointly: the means give
/// (E_b, c_L, c_R) (EstimateSystematicErrors); E_d = c_R / c_L is then a
/// third likelihood parameter of the run scatter (the bases' quadratic
/// expansion in E_d from builds at E_d0 and E_d0 +- 0.004, recentred at the
/// fit), with a weak prior (WheelNoiseFitOptions::E_d_prior_sigma) at the
/// means' value, and profiled out in the intervals: a path that retraces
/// itself (forward and back) hides E_d from the mean return error, but its
/// curvature still shapes the covariance. `build` turns systematic errors
/// into fit runs (NoiseRunsFromEndpoints / NoiseRunsFromTrajectories with
/// NoiseFitInputOptions::systematic) and must give the same runs in the
/// same order each time. *estimated receives the errors of the returned fit.
WheelNoiseFitSummary FitWheelNoiseWithSystematics(
    const std::function<std::vector<WheelNoiseFitRun>(const SystematicErrors&)>& build,
    const WheelNoiseFitOptions& options, SystematicEstimate* estimated);

/// The same joint fit on runs built without systematic errors (the
/// default NoiseFitInputOptions::systematic), each rebuilt in place
/// (RebuildNoiseRun) instead of building all runs again: memory for one set
/// of runs and their E_d sensitivities, the data read once (10^6 runs).
/// On return the runs' bases are those of the estimated errors.
WheelNoiseFitSummary FitWheelNoiseWithSystematics(std::vector<WheelNoiseFitRun>& runs,
                                                  const WheelNoiseFitOptions& options, SystematicEstimate* estimated);

/// Rebuilds a run's bases (first- and second-order) for the true robot with
/// systematic errors `x` (wheel travel c times odometry_travel, wheelbase
/// E_b times recorded_wheelbase_m), the way the builders below made them
/// (kelly_basis, with_second_order). The return error and the reference
/// covariance stay. A run without odometry_travel is left unchanged.
void RebuildNoiseRun(WheelNoiseFitRun& run, const SystematicErrors& x);

/// One run per endpoint row; `path` is what every run drove (wheelbase_m
/// resolves turn segments). Rows without etheta use the x-y block.
std::vector<WheelNoiseFitRun> NoiseRunsFromEndpoints(const EndpointData& data, const std::vector<PathSegment>& path,
                                                double wheelbase_m, const std::string& group_prefix,
                                                const NoiseFitInputOptions& options);

/// The fit run of one trajectory run (`path`, `robot` as below); nullopt
/// when the run lacks ground truth at its first or last sample.
std::optional<WheelNoiseFitRun> NoiseRunFromTrajectory(const TrajectoryRun& run, const std::string& path,
                                                       const RobotParams& robot, const std::string& group_prefix,
                                                       const NoiseFitInputOptions& options);

/// Undoes the turning-direction split (WheelNoiseFitRun::turn_grouped) of
/// a direction with a single run: its systematic mean would absorb that
/// run. NoiseRunsFromTrajectories calls it; call it after gathering runs of
/// NoiseRunFromTrajectory.
void MergeLoneTurnGroups(std::vector<WheelNoiseFitRun>& runs);

/// One run per trajectory run that has ground truth at its first and last
/// sample (others are counted in *skipped). Throws InputError (data.path)
/// when ticks cannot be converted (no ticks_per_rev).
std::vector<WheelNoiseFitRun> NoiseRunsFromTrajectories(const TrajectoryData& data, const RobotParams& robot,
                                                   const std::string& group_prefix,
                                                   const NoiseFitInputOptions& options, int* skipped = nullptr);

}  // namespace umbmark
