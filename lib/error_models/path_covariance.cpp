// Segment-by-segment covariance composition (eq. 23); see path_covariance.hpp.
#include "error_models/path_covariance.hpp"

#include <cmath>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "error_models/arc_jacobians.hpp"
#include "error_models/covariance_arc.hpp"
#include "error_models/covariance_line.hpp"
#include "error_models/covariance_turn.hpp"
#include "kinematics/diff_drive.hpp"

namespace umbmark {

const char* SegmentFormToString(SegmentForm f) {
  switch (f) {
    case SegmentForm::kLine: return "line";
    case SegmentForm::kTurn: return "turn";
    case SegmentForm::kArc: return "arc";
  }
  return "?";
}

SegmentForm SegmentFormOf(const WheelSegment& s) {
  if (s.left_m == s.right_m) return SegmentForm::kLine;
  if (s.left_m == -s.right_m) return SegmentForm::kTurn;
  return SegmentForm::kArc;
}

CovarianceBasis SegmentCovarianceBasis(const WheelSegment& s, double theta0, double wheelbase_m) {
  switch (SegmentFormOf(s)) {
    case SegmentForm::kLine: return LineCovarianceBasis(s.left_m, theta0, wheelbase_m);  // eq. 26
    case SegmentForm::kTurn:
      return TurnCovarianceBasis((s.right_m - s.left_m) / wheelbase_m, theta0, wheelbase_m);  // eq. 28
    case SegmentForm::kArc: return ArcCovarianceBasis(s.left_m, s.right_m, theta0, wheelbase_m);  // eq. 25
  }
  return {};
}

PathCovarianceSummary PredictPathCovariance(const std::vector<WheelSegment>& path, double wheelbase_m,
                                            const WheelNoise& noise, const PoseCovariance& P0, const Pose2& start) {
  if (!std::isfinite(wheelbase_m) || !(wheelbase_m > 0.0))
    throw InvalidOptions(fmt::format("wheelbase_m = {} must be a finite number > 0", wheelbase_m));
  if (auto e = noise.Check(); !e.empty()) throw InvalidOptions(e);
  PathCovarianceSummary out;
  Pose2 pose = start;
  for (const WheelSegment& s : path) {
    const Pose2 next = DiffDriveStep(pose, s.left_m, s.right_m, wheelbase_m, Integrator::kArc);
    const Eigen::Matrix3d phi = PoseErrorTransition(pose, next);  // eq. 21
    const CovarianceBasis u = SegmentCovarianceBasis(s, pose.theta, wheelbase_m);
    out.motion.A_L = phi * out.motion.A_L * phi.transpose() + u.A_L;  // eq. 23
    out.motion.A_R = phi * out.motion.A_R * phi.transpose() + u.A_R;
    pose = next;
    out.segment_end_poses.push_back(pose);
  }
  const Eigen::Matrix3d phi_total = PoseErrorTransition(start, pose);  // transitions compose (eq. 21)
  out.mean = pose;
  out.initial_term = phi_total * P0 * phi_total.transpose();
  out.covariance = out.initial_term + out.motion.Evaluate(noise);
  return out;
}

}  // namespace umbmark
