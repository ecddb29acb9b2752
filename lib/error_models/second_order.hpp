// Second-order correction to the first-order (Chong & Kleeman / Kelly)
// pose covariance: the shortening of the track by heading errors.
//
// Exactly, dx/ds = cos(theta + dtheta) = cos(theta) - sin(theta) dtheta
// - (1/2) cos(theta) dtheta^2 + ..., so to second order the position error
// gains p2 = -(1/2) int t(s) dtheta(s)^2 ds, with t = (cos theta, sin theta)
// and ds the signed travel of the axle midpoint. The heading error is
// exactly linear in the wheel noise (theta = (R - L)/B) and Gaussian, so
//   E[p2]      = -(1/2) int t C(s, s) ds,
//   Cov(p2)    = (1/2) int int t(s) t(s')^T C(s, s')^2 ds ds',
//   Cov(p2, first-order error) = 0 (odd moments of a Gaussian),
// where C(s, s') = Var(dtheta at min(s, s')) = P0_thth + (k_L^2 a + k_R^2 b)
// with a, b the travel of each wheel up to that point over B^2. The other
// second-order terms (along-track noise times heading noise) are smaller by
// the ratio of along-track error to path length times heading error and are
// left out. For Chong & Kleeman's 10 m forward and back (k_L = 0.0004,
// k_R = 0.00058, B = 0.371) this term is 3.7% of var(ex), which exact
// simulation shows and the first-order model misses (docs/noise-model.md).
//
// The double integral is evaluated in O(pieces) with suffix sums
// (C depends on min(s, s') only), by the midpoint rule over small pieces.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "error_models/path_spec.hpp"
#include "error_models/wheel_noise.hpp"
#include "kinematics/odometry.hpp"

namespace umbmark {

/// Cov(p2) = k_L^4 LL + k_L^2 k_R^2 LR + k_R^4 RR + c0 (k_L^2 L0 + k_R^2 R0)
///           + c0^2 P00, and E[p2] = k_L^2 mL + k_R^2 mR + c0 m0, where
/// c0 = P0(theta, theta). Only the x-y block is non-zero.
struct SecondOrderBasis {
  PoseCovariance LL = PoseCovariance::Zero(), LR = PoseCovariance::Zero(), RR = PoseCovariance::Zero();
  PoseCovariance L0 = PoseCovariance::Zero(), R0 = PoseCovariance::Zero(), P00 = PoseCovariance::Zero();
  Eigen::Vector3d mL = Eigen::Vector3d::Zero(), mR = Eigen::Vector3d::Zero(), m0 = Eigen::Vector3d::Zero();

  PoseCovariance Covariance(const WheelNoise& n, double p0_theta = 0.0) const {
    const double qL = n.k_L * n.k_L, qR = n.k_R * n.k_R;
    return qL * qL * LL + qL * qR * LR + qR * qR * RR + p0_theta * (qL * L0 + qR * R0) + p0_theta * p0_theta * P00;
  }
  Eigen::Vector3d Mean(const WheelNoise& n, double p0_theta = 0.0) const {
    return n.k_L * n.k_L * mL + n.k_R * n.k_R * mR + p0_theta * m0;
  }
};

/// Along a path of constant-curvature segments, each split into
/// `pieces_per_segment` pieces (midpoint rule, error O(pieces^-2)).
SecondOrderBasis SecondOrderHeadingBasis(const std::vector<WheelSegment>& path, double wheelbase_m,
                                         int pieces_per_segment = 256);

/// Along logged cumulative wheel travel, one piece per sample interval.
SecondOrderBasis SecondOrderHeadingBasis(const WheelTravel& travel, double wheelbase_m);

}  // namespace umbmark
