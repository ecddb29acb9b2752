// Kelly's transition-matrix covariance along a logged trajectory; see
// trajectory_covariance.hpp.
#include "error_models/trajectory_covariance.hpp"

#include <cmath>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "error_models/arc_jacobians.hpp"
#include "error_models/covariance_arc.hpp"

namespace umbmark {
namespace {

void CheckInputs(const WheelTravel& travel, double wheelbase_m) {
  if (!std::isfinite(wheelbase_m) || !(wheelbase_m > 0.0))
    throw InvalidOptions(fmt::format("wheelbase_m = {} must be a finite number > 0", wheelbase_m));
  if (travel.left_m.size() != travel.right_m.size())
    throw InvalidOptions(fmt::format("wheel travel arrays differ in size ({} left, {} right)", travel.left_m.size(),
                                     travel.right_m.size()));
}

}  // namespace

TrajectoryCovarianceSummary TrajectoryCovariance(const WheelTravel& travel, double wheelbase_m) {
  CheckInputs(travel, wheelbase_m);
  TrajectoryCovarianceSummary out;
  out.poses = IntegrateOdometry(travel, wheelbase_m, Pose2{}, Integrator::kArc);
  const std::size_t n = out.poses.size();
  if (n == 0) return out;
  const Pose2& end = out.poses.back();
  for (std::size_t i = 1; i < n; ++i) {
    const double dl = travel.left_m[i] - travel.left_m[i - 1];
    const double dr = travel.right_m[i] - travel.right_m[i - 1];
    if (dl == 0.0 && dr == 0.0) continue;
    const CovarianceBasis u = ArcCovarianceBasis(dl, dr, out.poses[i - 1].theta, wheelbase_m);
    const Eigen::Matrix3d phi = PoseErrorTransition(out.poses[i], end);  // Phi(t, tau_i), Kelly eq. 11
    out.motion.A_L += phi * u.A_L * phi.transpose();
    out.motion.A_R += phi * u.A_R * phi.transpose();
  }
  out.initial_transition = PoseErrorTransition(out.poses.front(), end);
  return out;
}

std::vector<CovarianceBasis> TrajectoryCovarianceAlong(const WheelTravel& travel, double wheelbase_m) {
  CheckInputs(travel, wheelbase_m);
  const std::vector<Pose2> poses = IntegrateOdometry(travel, wheelbase_m, Pose2{}, Integrator::kArc);
  std::vector<CovarianceBasis> out(poses.size());
  for (std::size_t i = 1; i < poses.size(); ++i) {
    const double dl = travel.left_m[i] - travel.left_m[i - 1];
    const double dr = travel.right_m[i] - travel.right_m[i - 1];
    const Eigen::Matrix3d phi = PoseErrorTransition(poses[i - 1], poses[i]);
    out[i].A_L = phi * out[i - 1].A_L * phi.transpose();
    out[i].A_R = phi * out[i - 1].A_R * phi.transpose();
    if (dl != 0.0 || dr != 0.0) out[i] += ArcCovarianceBasis(dl, dr, poses[i - 1].theta, wheelbase_m);
  }
  return out;
}

}  // namespace umbmark
