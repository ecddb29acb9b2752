// Dead reckoning along a logged trajectory: cumulative wheel travel per
// sample -> odometry pose per sample, starting from a given pose.
#pragma once

#include <cstddef>
#include <vector>

#include "core/robot.hpp"
#include "core/runs.hpp"
#include "kinematics/diff_drive.hpp"

namespace umbmark {

/// Cumulative left/right wheel travel [m] of a run under `robot` (the
/// parameters under which ticks are converted). Runs given in dist_*_m are
/// rescaled relative to `recorded`, the parameters that produced those
/// distances: travel * D_new / D_recorded. Throws InputError when ticks need
/// ticks_per_rev and it is missing.
struct WheelTravel {
  std::vector<double> left_m, right_m;
};
WheelTravel ComputeWheelTravel(const TrajectoryRun& run, const RobotParams& robot, const RobotParams& recorded);

/// Odometry pose at every sample, integrating the travel increments from
/// `start` (heading kept continuous, not wrapped).
std::vector<Pose2> IntegrateOdometry(const WheelTravel& travel, double wheelbase_m, const Pose2& start,
                                     Integrator integrator = Integrator::kArc);

}  // namespace umbmark
