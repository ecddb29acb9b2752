// Maximum-likelihood fit of Chong & Kleeman's wheel noise constants k_L,
// k_R (eq. 4) from return errors of repeated runs (their section 6.3 fits
// them by trial and error from 60 runs of 10 m forward and back).
//
// Model: the return error of run i (e = true final pose - odometry final
// pose, Borenstein & Feng eq. 3.1) is Gaussian,
//   e_i ~ N(mu_g(i), S_i),  S_i = k_L^2 A_L,i + k_R^2 A_R,i + Q_i(k) + M_i,
// where A_L,i, A_R,i are the motion covariance per unit k^2 along run i's
// path (closed forms, eqs. 23-28, or Kelly's form along a logged
// trajectory), Q_i the second-order heading term (k^4, second_order.hpp:
// without it k_L^2 comes out ~13% low and k_R^2 ~10% high for Chong &
// Kleeman's 10 m forward-and-back, and the 95% intervals cover the truth
// in only ~90% of simulated campaigns), M_i the covariance of the external
// reference's own error
// (MeasurementCovariance), and mu_g a free systematic mean per group
// (experiment and direction) -- residual systematic errors (UMBmark leaves
// some) must not be read as noise. Runs without a heading error use the x-y
// block. The group means are profiled out in closed form (generalised least
// squares) and the likelihood is maximised over (log k_L, log k_R) by
// Fisher scoring (wheel_noise_likelihood.hpp).
//
// Joint fit (uncalibrated robot): with per-run sensitivities of the bases
// to the diameter ratio E_d (WheelNoiseRunSensitivity), eps = E_d - E_d0 is
// a third likelihood parameter, with a weak Gaussian prior; it is profiled
// out in the intervals like the other k.
//
// 95% intervals: profile likelihood, {k : 2 (min NLL(k, .) - NLL_min) <=
// 3.8415} (chi^2_1), the minimum over the other k (and eps); the searches
// are in wheel_noise_likelihood.hpp. A bound the data cannot close is +inf.
//
// Goodness of fit: each of the six covariance elements of the residuals
// (pooled over runs, N - G degrees of freedom) against the model's average
// S_i, with the sampling standard error of a Gaussian sample covariance
// sqrt(sum_i S_jj S_kk + S_jk^2) / (N - G), so the user sees which elements
// the model cannot explain (Chong & Kleeman could not match all six).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/progress.hpp"
#include "error_models/path_spec.hpp"
#include "error_models/second_order.hpp"
#include "error_models/wheel_noise.hpp"
#include "core/pose2.hpp"

namespace umbmark {

/// The k^4 terms of S_i that the fit uses: second_order.hpp's LL, LR, RR
/// (the fit's runs start with no heading uncertainty, so the p0 terms are
/// zero). A third of SecondOrderBasis' size: with 10^6 runs and their E_d
/// sensitivities that is 0.9 GB less.
struct SecondOrderTerms {
  PoseCovariance LL = PoseCovariance::Zero(), LR = PoseCovariance::Zero(), RR = PoseCovariance::Zero();
  SecondOrderTerms() = default;
  SecondOrderTerms(const SecondOrderBasis& b) : LL(b.LL), LR(b.LR), RR(b.RR) {}  // NOLINT: implicit on purpose
};

/// One run's data for the fit.
struct WheelNoiseFitRun {
  std::string group;  ///< systematic-mean group (e.g. "fwd_back" or "exp2:cw")
  std::string run;    ///< run id (for reports)
  /// Where the run came from, for messages: index into
  /// WheelNoiseFitOptions::sources (-1: unknown) and its 1-based line (0: unknown).
  int source = -1;
  std::size_t line = 0;
  Eigen::Vector3d error = Eigen::Vector3d::Zero();  ///< [ex, ey, etheta] (etheta wrapped)
  bool has_theta = true;                            ///< false: etheta not measured
  CovarianceBasis basis;                            ///< motion covariance per unit k^2
  /// Second-order (heading-squared) term, k^4 terms of S_i (second_order.hpp);
  /// zero to fit the pure first-order model.
  SecondOrderTerms second_order;
  PoseCovariance measurement = PoseCovariance::Zero();  ///< reference error covariance M_i
  /// What the odometry measured, per constant-curvature piece (left, right
  /// wheel travel [m] under the recorded robot) and the recorded wheelbase:
  /// lets EstimateSystematicErrors predict this run's systematic return
  /// error. Empty when unknown.
  std::vector<WheelSegment> odometry_travel;
  double recorded_wheelbase_m = 0.0;
  /// How RebuildNoiseRun (wheel_noise_fit_data.hpp) builds the bases from
  /// odometry_travel: Kelly's form along the samples (trajectory runs) or
  /// the closed forms along the pieces (commanded paths); with or without
  /// the second-order terms.
  bool kelly_basis = false;
  bool with_second_order = false;
  /// The group is the experiment's split by turning direction (":cw" /
  /// ":ccw" appended by NoiseRunFromTrajectory), undone by
  /// MergeLoneTurnGroups when a direction has a single run.
  bool turn_grouped = false;
  /// Predicted systematic return error of this run (uncorrected E_b, E_d
  /// and scale along its own odometry travel; RebuildNoiseRun): run i's
  /// mean is mu_g + systematic_i. Runs of one group that drove different
  /// paths (free paths) have different systematic errors; one mean per
  /// group would read their spread as wheel noise.
  Eigen::Vector3d systematic = Eigen::Vector3d::Zero();
};

/// Covariance of the reference's error in a return error whose true
/// relative pose (start frame) is `relative`, when the reference measures
/// the start and the end pose each with independent noise sigma_xy [m] (per
/// axis) and sigma_theta [rad]:
///   M = diag(2 s_xy^2, 2 s_xy^2, s_th^2) + s_th^2 u u^T,  u = [y, -x, -1].
PoseCovariance MeasurementCovariance(double sigma_xy_m, double sigma_theta_rad, const Pose2& relative);

/// How run i's first-order bases move with the diameter ratio E_d about the
/// value E_d0 they were built at: basis(E_d0 + eps) = basis + eps d1 +
/// eps^2 d2; central differences of three builds
/// (FitWheelNoiseWithSystematics). The second-order terms stay at E_d0:
/// they are a correction of a few % whose own change over the fit's eps
/// (under 0.001 at the optimum) is far below the noise, and leaving out
/// their sensitivities saves 430 bytes per run.
struct WheelNoiseRunSensitivity {
  /// d1, d2 of A_L and A_R in single precision: eps d1 and eps^2 d2 are
  /// corrections of at most a few % of the basis, so 1e-7 relative is far
  /// below the noise; half the memory (144 bytes per run).
  Eigen::Matrix3f d1_L = Eigen::Matrix3f::Zero(), d1_R = Eigen::Matrix3f::Zero();
  Eigen::Matrix3f d2_L = Eigen::Matrix3f::Zero(), d2_R = Eigen::Matrix3f::Zero();
};

struct WheelNoiseFitOptions {
  /// Confidence level of the profile-likelihood intervals, in (0, 1).
  double confidence = 0.95;
  /// Fisher-scoring iteration limit of each optimisation (>= 10).
  int max_iterations = 200;
  /// Restricted maximum likelihood (REML): adds 1/2 sum_g log det(sum_i
  /// S_i^-1) so the noise estimate allows for the degrees of freedom the
  /// group means use (ML underestimates k^2 by about groups / runs).
  bool restricted = false;
  /// Small-sample threshold of the profile intervals: 2 dNLL <= t^2 of
  /// Student's t with N - G - P degrees of freedom (runs, groups, likelihood
  /// parameters; Bates & Watts' profile-t) instead of chi^2_1. With 60 runs
  /// chi^2_1 (3.84) covers the truth in about 94 % of simulated campaigns;
  /// t^2 (4.01) allows for the estimated means and parameters.
  bool small_sample = true;
  /// Compute the profile-likelihood intervals (the costly part). false:
  /// k_L_ci, k_R_ci are left NaN (inner fits of a joint estimate).
  bool intervals = true;
  /// Progress in stages (core/progress.hpp): the maximum-likelihood fit,
  /// then each of the two profile intervals. Default: none.
  ProgressCallback progress;
  /// Joint fit only: the weak Gaussian prior on eps = E_d - E_d0, centre
  /// (relative to the build value E_d0) and sigma (> 0). Default 0, 0.02:
  /// an uncalibrated robot's E_d is within a few percent of 1, and a design
  /// whose scatter says nothing about E_d keeps it near the value its
  /// means give.
  double E_d_prior_centre = 0.0;
  double E_d_prior_sigma = 0.02;
  /// Warm start (log k_L, log k_R, eps) from an earlier fit of the same
  /// runs (FitWheelNoiseWithSystematics: the fit without intervals, then the
  /// one with them); empty: the method-of-moments start.
  std::optional<Eigen::Vector3d> start;
  /// Worker threads of the likelihood passes over many runs (more than
  /// 16384; 0: all hardware threads). The result does not depend on it.
  int threads = 0;
  /// File names that WheelNoiseFitRun::source indexes; an InputError about
  /// a run names its file and line.
  std::vector<std::string> sources;
  /// Empty when valid, else a message naming the bad field.
  std::string Check() const;
};

/// Observed vs predicted for one covariance element.
struct CovarianceElementCheck {
  std::string element;       ///< "xx", "yy", "thth", "xy", "xth", "yth"
  double observed = 0.0;     ///< pooled residual covariance
  double predicted = 0.0;    ///< model average of S_i
  double standard_error = 0.0;
  double z = 0.0;            ///< (observed - predicted) / standard_error
  int runs = 0;              ///< runs that enter this element
};

struct WheelNoiseFitSummary {
  double k_L = 0.0, k_R = 0.0;                     ///< [m^1/2]
  std::array<double, 2> k_L_ci{0.0, 0.0};          ///< profile interval (high may be +inf)
  std::array<double, 2> k_R_ci{0.0, 0.0};
  double confidence = 0.95;
  double neg_log_likelihood = 0.0;                 ///< at the optimum (constants dropped)
  int runs = 0;
  std::vector<std::string> groups;                 ///< group names, first-seen order
  std::vector<int> group_of_run;                   ///< index into `groups` of each run
  /// Fitted mean return error of each group (mu_g plus the group's average
  /// WheelNoiseFitRun::systematic).
  std::vector<Eigen::Vector3d> group_means;
  std::vector<Eigen::Vector3d> residuals;          ///< e_i - systematic_i - mu_g(i), per run
  std::vector<PoseCovariance> predicted_run_covariance;  ///< S_i at the fit
  std::vector<CovarianceElementCheck> goodness_of_fit;   ///< six elements
  PoseCovariance observed_covariance = PoseCovariance::Zero();
  PoseCovariance predicted_covariance = PoseCovariance::Zero();
  int iterations = 0;
  std::string solver_message;
  /// Joint fit: the fitted eps = E_d - E_d0 and its standard error (Fisher
  /// information); 0 otherwise.
  double E_d_offset = 0.0, E_d_offset_se = 0.0;
  /// Likelihood passes over the runs (the cost with many runs).
  int likelihood_passes = 0;

  std::string BriefReport() const;
};

/// Fits k_L, k_R. Throws InvalidOptions for bad options, InputError (the
/// run's file and line from `sources`) when the data cannot identify the model (fewer than groups + 2 runs,
/// a group with a single run, non-finite errors), and QualityGateError when
/// the solver fails to converge or the likelihood is not finite at the fit.
/// With `E_d_sensitivity` (one per run), E_d is fitted jointly (see above);
/// InvalidOptions when its size differs from the runs'.
WheelNoiseFitSummary FitWheelNoise(const std::vector<WheelNoiseFitRun>& runs, const WheelNoiseFitOptions& options = {},
                                   const std::vector<WheelNoiseRunSensitivity>* E_d_sensitivity = nullptr);

/// Negative log-likelihood (constants dropped) at given k with the group
/// means profiled out; +inf when some S_i is not positive definite.
double WheelNoiseNegLogLikelihood(const std::vector<WheelNoiseFitRun>& runs, double k_L, double k_R);

}  // namespace umbmark
