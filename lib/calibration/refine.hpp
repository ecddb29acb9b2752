// Refined calibration (calibrate --refine): an exact, Ceres-based fit of the
// wheelbase and both wheel diameters with covariance, confidence intervals,
// an identifiability report and a checked solver outcome.
//
// Two inputs:
//  - Return errors of UMBmark squares (endpoint CSV, or trajectories reduced
//    to their return errors): the exact commanded-square model
//    (model/commanded_square.hpp) predicts every run's return error;
//    every run is a residual, weighted by the run-to-run scatter of its
//    (set, direction) group (rules and small-sample corrections:
//    refine_endpoint.cpp; choices and their checks: docs/refine.md).
//  - Trajectories with ground truth: odometry from the encoder samples vs
//    ground truth along the whole path of every run, sampled evenly in
//    travelled distance with a fixed number of poses per run (so a long run
//    does not swamp a short one), with a robust loss per pose.
//
// Unknowns theta = [E_b, E_d, E_s] relative to a reference robot (see
// refine_params.hpp); reported as RobotParams, a covariance over
// [wheelbase_m, wheel_diameter_left_m, wheel_diameter_right_m] (the
// contract's refined.covariance) and intervals for wheelbase, D_R, D_L, E_d,
// E_b (and E_s when it is free).
//
// Gauge / identifiability: the overall scale E_s (mean diameter) does not
// enter the return error of a square to first order (all four legs scale
// together and the turn angle only sees E_s / E_b), so by default it is held
// at 1 for return errors and left free for trajectories with ground truth
// (which measure distance directly); RefineOptions::scale overrides. A free
// parameter the data do not determine is reported as such (RefineError),
// never returned as a number.
//
// Errors: InvalidOptions for bad options; InputError for data the fit cannot
// use (unknown direction, non-finite value, no runs, a run without ground
// truth at its first sample); RefineError (a QualityGateError, exit 3) when
// the solver failed or the problem is rank deficient / ill-conditioned.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "calibration/refine_params.hpp"
#include "core/errors.hpp"
#include "core/robot.hpp"
#include "core/runs.hpp"
#include "evaluation/return_error.hpp"
#include "kinematics/diff_drive.hpp"

namespace umbmark {

/// How the overall scale E_s (mean wheel diameter) is treated.
enum class ScaleMode {
  /// Return errors: held (first-order unobservable). Trajectories: free,
  /// held (with a note) if the data do not determine it.
  kAuto,
  /// Held at RefineStart::E_s (default 1: the reference mean diameter
  /// factor is kept, as classic UMBmark does).
  kFixed,
  kFree    ///< estimated; RefineError if the data do not determine it
};
const char* ScaleModeToString(ScaleMode m);
std::optional<ScaleMode> ScaleModeFromString(std::string_view s);

/// How the trajectory fit's parameter covariance is formed.
enum class TrajectoryCovariance {
  /// Cluster-robust sandwich over runs: A^-1 (sum_r g_r g_r^T) A^-1 R/(R-1)
  /// (CR1), g_r the gradient of run r's cost, A the Hessian of the
  /// objective (the Ceres covariance without a loss; formed per pose with
  /// Ceres' rho', rho'' with one), R runs; intervals with Student t, R - 1
  /// degrees of freedom. Honest when poses of a run are correlated (they
  /// are: odometry error accumulates) and runs are independent. Needs at
  /// least p + 1 runs (p free parameters), else falls back to kSolverScaled
  /// with a note.
  kRunClustered,
  /// Ceres covariance times the residual variance 2 cost / (m - p): assumes
  /// independent poses, so it is optimistic along a trajectory.
  kSolverScaled
};
const char* TrajectoryCovarianceToString(TrajectoryCovariance c);
std::optional<TrajectoryCovariance> TrajectoryCovarianceFromString(std::string_view s);

/// Which poses of a trajectory run enter the fit.
enum class PoseSampling {
  /// RefineOptions::samples_per_run poses, evenly in travelled distance:
  /// every run weighs the same, however long or finely logged.
  kPerRun,
  /// Every sample with ground truth (runs weigh by their sample count).
  kEverySample
};
const char* PoseSamplingToString(PoseSampling s);
std::optional<PoseSampling> PoseSamplingFromString(std::string_view s);

/// The frame a trajectory run's odometry starts in (ground truth is
/// re-expressed in it).
enum class StartPose {
  /// The run's first ground-truth sample (the contract's evaluation frame):
  /// one noisy sample defines the whole run's frame.
  kFirstSample,
  /// The mean ground-truth pose over the initial standstill (the samples
  /// before either wheel moves): the frame's noise averages down by the
  /// number of standstill samples. Same as kFirstSample without standstill.
  kStandstillMean,
  /// Fitted per run: at every evaluation the rigid transform that best
  /// aligns the odometry positions with the ground truth (2-D Procrustes,
  /// closed form, differentiated through) is applied, i.e. the start pose
  /// is a nuisance profiled out of the objective.
  kFitted,
  /// The run's first ground-truth sample, seen through one frame error per
  /// recording session (TrajectoryRunSet): the motion-capture rigid body's
  /// yaw and origin against the axle midpoint, [a, o_x, o_y], fitted
  /// jointly with the parameters. Three unknowns per session instead of
  /// three per run (kFitted), so what a session shares is modelled and
  /// nothing else is absorbed (docs/calibration-comparison.md).
  kSessionFrame
};
const char* StartPoseToString(StartPose s);
std::optional<StartPose> StartPoseFromString(std::string_view s);

/// Starting point, relative to the reference robot. Pass the classic UMBmark
/// solution (UmbmarkSummary::selected.E_b, .E_d) for return errors.
struct RefineStart {
  double E_b = 1.0;
  double E_d = 1.0;
  double E_s = 1.0;
};

struct RefineOptions {
  // ---- common ----
  /// Initial theta. Default: the reference robot itself.
  RefineStart start;
  /// Overall scale handling, see ScaleMode. Default kAuto.
  ScaleMode scale = ScaleMode::kAuto;
  /// Confidence level of the reported intervals, in (0, 1). Default 0.95.
  double confidence = 0.95;
  /// A free parameter whose standard deviation exceeds this is "not
  /// determined" (all unknowns are factors near 1, so 0.01 = 1 %: a
  /// correction that uncertain is no calibration; systematic errors of a
  /// real robot are of that order). Default 0.01.
  double max_relative_sigma = 0.01;
  /// Largest acceptable condition number of the column-normalised weighted
  /// Jacobian over the free parameters (collinearity); above it the problem
  /// is reported as rank deficient. Default 1e8 (relative precision 1e-8 of
  /// the solution's separable directions in double arithmetic).
  double max_condition_number = 1e8;
  /// Levenberg-Marquardt iteration limit; not converging within it is a
  /// failure. Default 100.
  int max_num_iterations = 100;
  /// Ceres convergence tolerances (see ceres::Solver::Options). Tight
  /// defaults (1e-12): the problems are tiny and noise-free data must be
  /// recovered to 1e-6 relative.
  double function_tolerance = 1e-12;
  double gradient_tolerance = 1e-12;
  double parameter_tolerance = 1e-12;
  /// Threads Ceres may use for residual evaluation. Default 1.
  int num_threads = 1;

  // ---- return errors (squares) ----
  /// The run ends with the fourth turn (see commanded_square.hpp). Default true.
  bool final_turn = true;
  /// Use etheta_rad where every run of a group has it. Default true.
  bool use_heading = true;
  /// A (set, direction) group with at least max(this, d + 3) runs (d = 2,
  /// or 3 with heading) is weighted by the inverse of its own scatter
  /// covariance; smaller groups use the set's scatter pooled over both
  /// directions (mirrored), then a pooled diagonal, then the prior sigmas
  /// (refine_endpoint.cpp). Scatter covariances are corrected for small
  /// samples and intervals use a Student t quantile. Default 6 (the
  /// smallest count with a defined correction for d = 3).
  int min_runs_for_group_covariance = 6;
  /// Added in quadrature to every scatter sigma so noise-free data still
  /// give finite weights: 1e-5 m and 1e-5 rad (far below any measurement).
  double sigma_floor_xy_m = 1e-5;
  double sigma_floor_theta_rad = 1e-5;
  /// Used only when there are too few runs to measure the scatter (see
  /// above): assumed per-axis sigmas of a return error. Default 5 mm and 5 mrad; the
  /// intervals then reflect this assumption (a note says so).
  double prior_sigma_xy_m = 0.005;
  double prior_sigma_theta_rad = 0.005;

  // ---- trajectories with ground truth ----
  /// Integrator of the odometry between encoder samples. Default kArc.
  Integrator integrator = Integrator::kArc;
  /// Sampled poses per run, evenly spaced in travelled distance
  /// (|d_L| + |d_R|)/2 so spot turns are sampled too and standstill is not;
  /// every run weighs the same. The last ground-truth sample is always one.
  /// Default 100 (used with PoseSampling::kPerRun).
  int samples_per_run = 100;
  /// See PoseSampling. Default kPerRun.
  PoseSampling sampling = PoseSampling::kPerRun;
  /// See StartPose. Default kFirstSample: the smallest worst-case loss to
  /// plain least squares across June days, simulated frame errors and the
  /// issue's other night (docs/calibration-comparison.md, "Second round").
  StartPose start_pose = StartPose::kFirstSample;
  /// Metres per radian for the heading residual; <= 0 means the reference
  /// wheelbase (a heading error of 1 rad counts like a position error of
  /// one wheelbase: the displacement of a wheel contact point). Default 0.
  double heading_length_m = 0.0;
  /// Multiplies the heading residual (h = heading_weight * heading length);
  /// 0 = position-only residual. Default 1 (the smallest worst-case loss
  /// to plain least squares: docs/calibration-comparison.md, "Second round").
  double heading_weight = 1.0;
  /// Robust loss per sampled pose and its scale [m]. Default Huber, 0.02 m:
  /// about twice the path residual of a calibrated small robot, so ordinary
  /// poses stay quadratic and a bump or a tracking glitch counts linearly.
  RobustLoss loss = RobustLoss::kHuber;
  double loss_scale_m = 0.02;
  /// See TrajectoryCovariance. Default kRunClustered.
  TrajectoryCovariance covariance = TrajectoryCovariance::kRunClustered;

  /// Empty when valid, else a message naming the bad field, its value and
  /// the rule it broke.
  std::string Check() const;
};

/// One set of square runs recorded with the same robot parameters and side.
struct SquareRunSet {
  double side_m = 0.0;
  RobotParams recorded;               ///< the parameters the odometry used
  std::vector<ReturnError> errors;    ///< direction "cw" or "ccw"
  std::string source;                 ///< file name for messages
};

/// One set of trajectory runs recorded with the same robot parameters.
struct TrajectoryRunSet {
  RobotParams recorded;  ///< ticks_per_rev needed when the runs carry ticks
  const TrajectoryData* data = nullptr;  ///< not owned; must outlive the call
};

/// value +- half width at RefineSummary::confidence.
struct RefineInterval {
  double value = 0.0;
  double sigma = 0.0;  ///< standard deviation (0 when fixed)
  double low = 0.0, high = 0.0;
};

/// The quantities with their intervals (E_s: sigma 0 when fixed).
struct RefineIntervals {
  RefineInterval wheelbase_m, wheel_diameter_right_m, wheel_diameter_left_m, E_d, E_b, E_s;
};

struct RefineIdentifiability {
  std::vector<std::string> free_parameters;   ///< of E_b, E_d, E_s
  std::vector<std::string> fixed_parameters;
  /// Singular values of the weighted Jacobian over the free parameters
  /// (descending). The unknowns are dimensionless factors, so 1/s is the
  /// standard deviation along the matching direction (before any
  /// covariance correction).
  std::vector<double> singular_values;
  /// Condition number of the column-normalised weighted Jacobian
  /// (collinearity of the free parameters' effects); inf when singular.
  double condition_number = 0.0;
  /// Standard deviation of each free parameter (same order), from the
  /// reported covariance.
  std::vector<double> sigma;
  std::vector<std::string> determined, undetermined;
  bool rank_deficient = false;
  std::string message;  ///< human-readable verdict
};

struct RefineSolverReport {
  std::string termination_type;  ///< ceres::TerminationTypeToString
  std::string message;
  std::string brief_report;
  bool usable = false;     ///< IsSolutionUsable() and converged
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;
  int residual_evaluations = 0, jacobian_evaluations = 0;
  double solve_time_s = 0.0;
};

enum class RefineInputKind { kReturnErrors, kTrajectories };
const char* RefineInputKindToString(RefineInputKind k);
std::optional<RefineInputKind> RefineInputKindFromString(std::string_view s);

/// How one group of return errors was weighted.
struct RefineGroupWeighting {
  std::string set;        ///< source of the set
  std::string direction;  ///< cw | ccw
  double side_m = 0.0;
  int runs = 0;
  bool heading = false;       ///< etheta_rad used
  std::string method;         ///< group_covariance | pooled_diagonal | prior
  double sigma_x_m = 0.0, sigma_y_m = 0.0, sigma_theta_rad = 0.0;  ///< per-axis sigma used
};

struct RefineSummary {
  RefineInputKind input = RefineInputKind::kReturnErrors;
  RobotParams reference;  ///< what the relative factors refer to
  RobotParams refined;    ///< wheelbase E_b*b, diameters c_L*D_L, c_R*D_R
  double E_b = 1.0, E_d = 1.0, E_s = 1.0, c_L = 1.0, c_R = 1.0;
  bool scale_free = false;

  /// Covariance over covariance_order (contract: wheelbase_m,
  /// wheel_diameter_left_m, wheel_diameter_right_m) [m^2].
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  std::vector<std::string> covariance_order{"wheelbase_m", "wheel_diameter_left_m", "wheel_diameter_right_m"};
  /// Covariance of theta = [E_b, E_d, E_s] (zero row/column when fixed).
  Eigen::Matrix3d theta_covariance = Eigen::Matrix3d::Zero();
  std::string covariance_method;  ///< group_scatter | prior | run_clustered | solver_scaled

  double confidence = 0.95;
  /// Interval half width = quantile * sigma: normal, or Student t with
  /// `dof` degrees of freedom when the covariance is estimated from runs.
  double quantile = 0.0;
  std::optional<double> dof;
  RefineIntervals intervals;

  double final_cost = 0.0;  ///< Ceres cost, 1/2 sum of squared weighted residuals
  /// 2 cost / (residuals - free parameters): ~1 when the return-error weights
  /// match the scatter and the model fits.
  double reduced_chi2 = 0.0;
  int runs = 0;
  int residuals = 0;
  int sampled_poses = 0;  ///< trajectories only
  /// Trajectories only: the residual's settings (RefineOptions), as used.
  struct TrajectorySettings {
    std::string sampling, start_pose, loss;
    double heading_length_m = 0.0;  ///< metres per radian after heading_weight
    double loss_scale_m = 0.0;
  } trajectory_settings;

  RefineSolverReport solver;
  RefineIdentifiability identifiability;
  std::vector<RefineGroupWeighting> groups;  ///< return errors only
  std::vector<std::string> notes;            ///< decisions a user should know about
};

/// Thrown when the fit ran but its result must not be reported (solver
/// failure, rank-deficient or ill-conditioned problem). Carries what is
/// known (solver report, identifiability) for the app to print.
class RefineError : public QualityGateError {
 public:
  RefineError(const std::string& what, RefineSummary summary)
      : QualityGateError(what), summary_(std::move(summary)) {}
  const RefineSummary& summary() const { return summary_; }

 private:
  RefineSummary summary_;
};

/// Refines from return errors of squares. `reference` is the robot the
/// result is expressed against (normally the sets' common recorded robot).
RefineSummary RefineFromReturnErrors(const std::vector<SquareRunSet>& sets, const RobotParams& reference,
                                     const RefineOptions& options);

/// Refines from trajectories with ground truth (every run needs ground truth
/// at its first sample; samples without ground truth are skipped).
RefineSummary RefineFromTrajectories(const std::vector<TrajectoryRunSet>& sets, const RobotParams& reference,
                                     const RefineOptions& options);

/// Plain least squares on trajectories, the comparison row of
/// docs/calibration-comparison.md: position-only residual at every sample
/// with ground truth, no robust loss, each run's frame at its first sample,
/// wheelbase and both diameters free. The refined defaults are chosen to
/// beat it on held-out recordings.
RefineOptions PlainLeastSquaresOptions();

/// Corrected robot for theta relative to `reference`.
RobotParams ApplyRefinedFactors(const RobotParams& reference, double E_b, double E_d, double E_s);

/// The contract's `refined` object: parameters, covariance, covariance_order,
/// final_cost, plus E_b, E_d, E_s, intervals, solver, identifiability,
/// weighting and notes.
nlohmann::json RefinedToJson(const RefineSummary& summary);

/// A few readable lines (the app decides whether to print them).
std::string RefineReport(const RefineSummary& summary);

}  // namespace umbmark
