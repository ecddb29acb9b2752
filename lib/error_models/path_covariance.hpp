// Pose mean and covariance after a path of constant-curvature segments
// (Chong & Kleeman eq. 23 applied segment by segment):
//   Cov(S_k) = Phi_k Cov(S_{k-1}) Phi_k^T + Cov(U_k)
// with Phi_k the pose-error transition of segment k (eq. 21) and Cov(U_k)
// its motion covariance: eq. 26 for lines (L == R), eq. 28 for spot turns
// (L == -R), eq. 25 for any other arc (covariance_arc.hpp). The mean is the
// noise-free pose (first-order model), integrated with exact arcs.
#pragma once

#include <vector>

#include "error_models/path_spec.hpp"
#include "error_models/wheel_noise.hpp"
#include "core/pose2.hpp"

namespace umbmark {

/// Which closed form a segment uses.
enum class SegmentForm { kLine, kTurn, kArc };
const char* SegmentFormToString(SegmentForm f);
SegmentForm SegmentFormOf(const WheelSegment& s);

/// Motion covariance basis of one segment starting at heading theta0 [rad]
/// (eq. 26, 28 or 25 by SegmentFormOf). Precondition: wheelbase_m > 0.
CovarianceBasis SegmentCovarianceBasis(const WheelSegment& s, double theta0, double wheelbase_m);

struct PathCovarianceSummary {
  /// Noise-free final pose; theta is continuous (not wrapped).
  Pose2 mean;
  /// Full covariance: initial_term + motion.Evaluate(noise).
  PoseCovariance covariance = PoseCovariance::Zero();
  /// Phi(end, start) P0 Phi^T (eq. 23, first term).
  PoseCovariance initial_term = PoseCovariance::Zero();
  /// Motion covariance per unit k_L^2 / k_R^2 at the end of the path.
  CovarianceBasis motion;
  /// Pose after each segment (theta continuous).
  std::vector<Pose2> segment_end_poses;
};

/// Propagates P0 (covariance of the start pose) along `path` from `start`.
/// Throws InvalidOptions when wheelbase_m <= 0 or the noise fails Check().
PathCovarianceSummary PredictPathCovariance(const std::vector<WheelSegment>& path, double wheelbase_m,
                                            const WheelNoise& noise, const PoseCovariance& P0, const Pose2& start = {});

}  // namespace umbmark
