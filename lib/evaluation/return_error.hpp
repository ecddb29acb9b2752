// Return errors e = absolute - odometry (Borenstein & Feng eq. 3.1) of each
// run (core/runs.hpp ReturnError), from an endpoint file or computed from
// trajectories.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/robot.hpp"
#include "core/runs.hpp"
#include "kinematics/diff_drive.hpp"

namespace umbmark {

std::vector<ReturnError> ReturnErrorsFromEndpoints(const EndpointData& data);

/// Odometry with `params` from the first ground-truth pose to the last sample
/// with ground truth, compared with ground truth there (start frame).
std::vector<ReturnError> ReturnErrorsFromTrajectories(const TrajectoryData& data, const RobotParams& params,
                                                      const RobotParams& recorded, Integrator integrator);

}  // namespace umbmark
