// Odometry and ground truth of one trajectory run, side by side in the run's
// start frame (contract: both start at (0, 0, 0); ground truth is
// re-expressed in the frame of its first sample).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/robot.hpp"
#include "core/runs.hpp"
#include "kinematics/diff_drive.hpp"
#include "core/pose2.hpp"

namespace umbmark {

struct RunTrack {
  std::vector<Pose2> odometry;      ///< per sample, start frame, continuous heading
  std::vector<Pose2> ground_truth;  ///< per sample, start frame (NaN where not measured)
  std::vector<bool> has_ground_truth;
  /// Total rotation of the ground truth over the run [rad], from the sum of
  /// wrapped heading increments between measured samples (so wrapped and
  /// unwrapped ground truth give the same answer). About -2*pi for a cw square.
  double gt_total_rotation_rad = 0.0;
  std::size_t last_gt = 0;  ///< index of the last sample with ground truth
};

/// Integrates odometry with `params` (ticks converted with `params`; dist_*
/// columns rescaled relative to `recorded`) from the first ground-truth pose.
/// Throws InputError naming `file` (the run's CSV) when the run has no
/// ground truth at its first sample.
RunTrack TrackRun(const TrajectoryRun& run, const std::string& file, const RobotParams& params,
                  const RobotParams& recorded, Integrator integrator);

}  // namespace umbmark
