// The lidar's mounting pose as the scans and the wheels see it, to check the
// pose the import was given (/tf_static, --scan-pose, or the origin). Over
// short stretches of a run (i -> j) the lidar's registered motion L and the
// wheel odometry's axle motion A are the same rigid motion seen from two
// frames tied by the mount M = axle_T_lidar (hand-eye calibration):
//
//     M L = A M     rotation:    theta_L = theta_A
//                   translation: R(phi) t_L + (I - R(theta_A)) m = t_A
//
// The translation equation is linear in (c, s, m_x, m_y) with R(phi) =
// [c -s; s c]; least squares over all stretches gives the yaw phi =
// atan2(s, c), the position m (determined by the turns) and hypot(c, s),
// the ratio of the wheels' scale to the lidar's ranges (about 1). A lidar
// whose scans turn the other way than the wheels is mirrored (mounted
// upside down, or its beam angles run the other way) - or the wheels are
// swapped; the gyro tells which (the caller's job).
#pragma once

#include <cstddef>
#include <vector>

#include "core/pose2.hpp"

namespace umbmark::scan {

/// One stretch: the lidar's motion (registered, in its own frame) and the
/// axle's (wheel odometry) over the same time span.
struct MountPair {
  Pose2 lidar, axle;
};

struct MountEstimate {
  double yaw_rad = 0.0;       ///< phi
  double x_m = 0.0, y_m = 0.0;
  double scale = 1.0;         ///< hypot(c, s): wheel distances over lidar distances
  /// sum theta_L theta_A / sum theta_A^2: +1 when the scans turn with the
  /// wheels, -1 when mirrored.
  double turn_ratio = 1.0;
  bool mirrored = false;      ///< turn_ratio < 0 (then the yaw and position are of the mirrored lidar)
  bool position_determined = false;  ///< the turns pin m_x, m_y (well-conditioned normal matrix)
  std::size_t pairs = 0;
  double straight_m = 0.0, turned_rad = 0.0;  ///< how much motion the estimate rests on
};

/// Least squares over `pairs`; with fewer than 3 pairs or less than 0.3 m of
/// travel, `pairs` is 0 in the result (nothing estimated).
MountEstimate EstimateMount(const std::vector<MountPair>& pairs);

/// The lidar's motion between two lidar poses from the axle's motion and
/// the mount: M^-1 A M (and its inverse, for the axle poses of a track).
Pose2 LidarMotionFromAxle(const Pose2& mount, const Pose2& axle_motion);

}  // namespace umbmark::scan
