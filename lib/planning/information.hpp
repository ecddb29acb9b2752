// How precisely a set of runs determines what `calibrate` and `fit-noise`
// estimate: the Fisher information (or, for the plain least-squares fit,
// its sandwich covariance) of the models umbmark fits, evaluated at the
// recorded robot, from the runs' wheel travel alone (no simulation).
//
// Calibration parameters theta = [E_b, E_d, E_s] (docs/refine.md: wheelbase
// factor, diameter-ratio factor, overall scale; c_L = 2 E_s/(E_d+1), c_R =
// 2 E_s/(1/E_d+1)).
//
// 1. Ground truth along the path (motion capture, scans): the plain least
//    squares calibrate recommends (position residual at every ground-truth
//    sample, each run's frame at its first sample, scale free;
//    PlainLeastSquaresOptions). With r_k = p_odo,k(theta) - g_k and
//    J_k = d p_odo,k / d theta (central differences of IntegrateOdometry),
//    the estimate is theta^ - theta = -A^-1 sum_k J_k' dg_k, A = sum J_k' J_k,
//    so Cov(theta^) = A^-1 B A^-1, B = sum over runs of Var(sum_k J_k' dg_k),
//    with dg_k the ground truth's deviation from the odometry path:
//     - wheel noise (Chong & Kleeman eq. 4, variance k^2 |travel| per wheel
//       per sample interval j), propagated to every later sample by Kelly's
//       transition Phi(t_k, t_j) = [1 0 -(y_k - y_j); 0 1 (x_k - x_j)];
//       the sums over k are suffix sums, so one pass per run;
//     - the ground truth's own white noise sigma_xy per axis and sample;
//     - the noise of the first sample, which sets the run's frame: a shift
//       n0 (sigma_xy) moves every sample by -n0, a yaw m0 (sigma_theta)
//       rotates it, dg_k = m0 (y_k, -x_k).
// 2. Ground truth at the end points only (tape): classic UMBmark (the mean
//    estimator) from the centres of gravity of the cw and ccw return
//    errors, by the delta method on EstimateFromCentres; the return error
//    covariance of a run is the closed form along the commanded square
//    (PredictPathCovariance) plus the reference's noise at both ends
//    (MeasurementCovariance). It holds the overall scale at the recorded
//    value: closed paths with end-point ground truth never determine it
//    (Kelly; docs/refine.md "The scale of a square").
// 3. fit-noise (REML): S_i = k_L^2 A_L,i + k_R^2 A_R,i + M_i per run; the
//    information on q = (k_L^2, k_R^2) is 1/2 tr(S^-1 A_a S^-1 A_b) per
//    run, and a group (a systematic mean) of n runs loses one run's worth
//    of it (REML: n - 1 degrees of freedom of a Gaussian covariance), so
//    each run counts (n_g - 1)/n_g. sigma(k) = sigma(q) / (2 k). The
//    second-order term and the joint E_d are left out (a few % of k).
// Half-widths are z_0.975 = 1.96 standard deviations: the estimate lies
// within them of the truth in 95 % of campaigns (first-order model).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "error_models/wheel_noise.hpp"
#include "kinematics/odometry.hpp"

namespace umbmark::planning {

/// Where the ground truth sees the robot and how noisy it is.
struct GroundTruthModel {
  /// true: every sample (motion capture, scans); false: the first and last
  /// sample of a run only (tape).
  bool along_path = true;
  double sigma_xy_m = 3e-4;      ///< per axis and measured pose [m], >= 0
  double sigma_theta_rad = 1e-3;  ///< per measured pose [rad], >= 0
};

/// Sandwich terms of the plain least-squares fit for one run (see above).
struct LeastSquaresTerms {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();  ///< sum J' J
  Eigen::Matrix3d B = Eigen::Matrix3d::Zero();  ///< Var(sum J' dg)
  LeastSquaresTerms& Add(const LeastSquaresTerms& o, double times = 1.0) {
    A += times * o.A;
    B += times * o.B;
    return *this;
  }
  /// A^-1 B A^-1 (pseudo-inverse where A is singular: the caller checks
  /// the condition number).
  Eigen::Matrix3d Covariance() const;
};

/// d p_odo,k / d theta at every sample (2 x 3 blocks stacked: rows 2k,
/// 2k + 1), theta = [E_b, E_d, E_s] at [1, 1, 1].
Eigen::MatrixXd OdometryJacobian(const WheelTravel& travel, double wheelbase_m);

/// Plain least-squares terms of one run. `ground_truth` marks the samples
/// with ground truth (empty: all); sample 0 sets the frame.
LeastSquaresTerms PathLeastSquaresTerms(const WheelTravel& travel, const std::vector<bool>& ground_truth,
                                        double wheelbase_m, const WheelNoise& noise, const GroundTruthModel& gt);

/// Covariance of (E_d, E_b) of classic UMBmark (mean estimator) from the
/// per-run return-error covariances (x, y block) of n_cw cw and n_ccw ccw
/// runs of side L.
Eigen::Matrix2d ClassicCovariance(const Eigen::Matrix2d& run_cov_cw, int n_cw, const Eigen::Matrix2d& run_cov_ccw,
                                  int n_ccw, double side_m, double wheelbase_m);

/// One kind of run for the wheel-noise information: its return-error
/// covariance basis and reference covariance, how many such runs, and its
/// systematic-mean group.
struct NoiseRunModel {
  std::string group;
  CovarianceBasis basis;
  Eigen::Matrix3d measurement = Eigen::Matrix3d::Zero();
  double count = 1.0;
};

/// Information on (k_L^2, k_R^2) of one run with return-error covariance
/// basis `basis` and reference covariance `measurement`, ML (no group
/// correction): 1/2 tr(S^-1 A_a S^-1 A_b). Zero when S is not positive
/// definite.
Eigen::Matrix2d RunNoiseInformation(const CovarianceBasis& basis, const Eigen::Matrix3d& measurement,
                                    const WheelNoise& noise);

/// REML information on (k_L^2, k_R^2) (see above).
Eigen::Matrix2d NoiseInformation(const std::vector<NoiseRunModel>& runs, const WheelNoise& noise);

/// 95 % half-widths of k_L, k_R from that information (+inf where it is
/// singular or k is 0).
Eigen::Vector2d NoiseHalfWidths(const Eigen::Matrix2d& information, const WheelNoise& noise);

/// z_0.975.
inline constexpr double kZ95 = 1.959963984540054;

}  // namespace umbmark::planning
