// Numerical reference for the closed forms: many-segment propagation of
// eq. (2) with the EXACT Jacobians of each small step, obtained by automatic
// differentiation (ceres::Jet) of the exact-arc step DiffDriveStep -- so it
// shares no algebra with eqs. 25-28. Each segment is split into N equal
// steps; step i adds G_i diag(k_L^2 |l_i|, k_R^2 |r_i|) G_i^T after
// transporting the previous covariance with F_i (eq. 2). The discretisation
// error is an even power series in 1/N (midpoint-rule structure), so the
// result is Richardson-extrapolated over N, 2N, 4N to O(N^-6).
#pragma once

#include <vector>

#include <ceres/jet.h>

#include "error_models/path_spec.hpp"
#include "error_models/wheel_noise.hpp"
#include "kinematics/diff_drive.hpp"

namespace umbmark {

struct NumericalPropagationOptions {
  /// Steps per segment at the coarsest level (>= 1).
  int steps_per_segment = 2048;
  /// Richardson levels: 1 = plain propagation with N steps, 2 = N and 2N,
  /// 3 = N, 2N, 4N.
  int richardson_levels = 3;
};

namespace detail {

/// Propagates basis and P0 through `path` with n equal steps per segment.
inline void PropagateSteps(const std::vector<WheelSegment>& path, double B, int n, CovarianceBasis& basis,
                           PoseCovariance& p0_term) {
  using Jet = ceres::Jet<double, 5>;
  Pose2 pose{};
  for (const WheelSegment& seg : path) {
    const double l = seg.left_m / n, r = seg.right_m / n;
    for (int i = 0; i < n; ++i) {
      const Pose2T<Jet> p{Jet(pose.x, 0), Jet(pose.y, 1), Jet(pose.theta, 2)};
      const Pose2T<Jet> q = DiffDriveStep(p, Jet(l, 3), Jet(r, 4), Jet(B), Integrator::kArc);
      Eigen::Matrix3d F;
      Eigen::Matrix<double, 3, 2> G;
      const Jet* rows[3] = {&q.x, &q.y, &q.theta};
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) F(a, b) = rows[a]->v[b];
        G(a, 0) = rows[a]->v[3];
        G(a, 1) = rows[a]->v[4];
      }
      basis.A_L = F * basis.A_L * F.transpose() + std::abs(l) * G.col(0) * G.col(0).transpose();
      basis.A_R = F * basis.A_R * F.transpose() + std::abs(r) * G.col(1) * G.col(1).transpose();
      p0_term = F * p0_term * F.transpose();
      pose = {q.x.a, q.y.a, q.theta.a};
    }
  }
}

}  // namespace detail

/// Covariance basis of the motion and the transported P0 at the end of
/// `path` (wheelbase B), numerically. Returns the basis; *p0_term (optional)
/// receives Phi P0 Phi^T.
inline CovarianceBasis NumericalPathCovarianceBasis(const std::vector<WheelSegment>& path, double B,
                                                    const PoseCovariance& P0 = PoseCovariance::Zero(),
                                                    PoseCovariance* p0_term = nullptr,
                                                    const NumericalPropagationOptions& options = {}) {
  std::vector<CovarianceBasis> level;
  PoseCovariance p0_out = P0;
  for (int k = 0; k < options.richardson_levels; ++k) {
    CovarianceBasis b;
    PoseCovariance p = P0;
    detail::PropagateSteps(path, B, options.steps_per_segment << k, b, p);
    level.push_back(b);
    p0_out = p;  // exact at any N (transitions compose)
  }
  // Richardson tableau for an error series in h^2, h^4, ...
  for (int m = 1; m < static_cast<int>(level.size()); ++m) {
    const double f = static_cast<double>(1 << (2 * m));  // 4^m
    for (int k = static_cast<int>(level.size()) - 1; k >= m; --k) {
      level[k].A_L = (f * level[k].A_L - level[k - 1].A_L) / (f - 1.0);
      level[k].A_R = (f * level[k].A_R - level[k - 1].A_R) / (f - 1.0);
    }
  }
  if (p0_term) *p0_term = p0_out;
  return level.back();
}

}  // namespace umbmark
