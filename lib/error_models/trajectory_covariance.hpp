// Pose covariance along a logged trajectory (Kelly, "General Solution for
// Linearized Stochastic Error Propagation in Vehicle Odometry", eqs. 9 and
// 11): with the transition matrix
//   Phi(t, tau) = [1 0 -(y(t) - y(tau)); 0 1 (x(t) - x(tau)); 0 0 1]
// the covariance at t is
//   P(t) = Phi(t,0) P(0) Phi(t,0)^T + sum_i Phi(t,tau_i) U_i Phi(t,tau_i)^T
// where U_i is the covariance added by the wheel noise (Chong & Kleeman
// eq. 4) between samples i-1 and i. Between two encoder samples both wheels
// are taken to turn at a constant ratio (a constant-curvature arc, as the
// odometry integrates them), so U_i is exact: eq. 25 / its quadrature
// (covariance_arc.hpp) on the wheel travel increments, evaluated at the
// sample's end pose tau_i. The trajectory comes from the encoders alone.
#pragma once

#include <vector>

#include "error_models/wheel_noise.hpp"
#include "kinematics/odometry.hpp"
#include "core/pose2.hpp"

namespace umbmark {

struct TrajectoryCovarianceSummary {
  /// Odometry pose at every sample (exact arcs, theta continuous).
  std::vector<Pose2> poses;
  /// Motion covariance per unit k^2 at the last sample (Kelly's sum).
  CovarianceBasis motion;
  /// Phi(t_end, 0): maps an initial pose error onto the final one.
  Eigen::Matrix3d initial_transition = Eigen::Matrix3d::Identity();

  PoseCovariance Covariance(const WheelNoise& noise, const PoseCovariance& P0) const {
    return initial_transition * P0 * initial_transition.transpose() + motion.Evaluate(noise);
  }
};

/// Kelly's transition-matrix form at the end of the trajectory. `travel`
/// holds cumulative wheel travel per sample [m] (ComputeWheelTravel).
/// Throws InvalidOptions when wheelbase_m <= 0 or the arrays differ in size.
TrajectoryCovarianceSummary TrajectoryCovariance(const WheelTravel& travel, double wheelbase_m);

/// The motion covariance basis at EVERY sample (recursive form of the same
/// solution, eq. 23 of Chong & Kleeman sample by sample); element 0 is zero.
std::vector<CovarianceBasis> TrajectoryCovarianceAlong(const WheelTravel& travel, double wheelbase_m);

}  // namespace umbmark
