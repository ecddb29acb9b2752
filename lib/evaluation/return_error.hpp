// Return errors e = absolute - odometry (Borenstein & Feng eq. 3.1) of each
// run, from an endpoint file or computed from trajectories.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/robot.hpp"
#include "core/runs.hpp"
#include "kinematics/diff_drive.hpp"

namespace umbmark {

struct ReturnError {
  std::string run;
  std::string direction;
  double ex_m = 0.0, ey_m = 0.0;
  std::optional<double> etheta_rad;  ///< wrapped to (-pi, pi]
  std::size_t line = 0;              ///< source line of the run (first sample)
  /// Ground-truth total rotation [rad] (trajectory input only).
  std::optional<double> gt_total_rotation_rad;
};

std::vector<ReturnError> ReturnErrorsFromEndpoints(const EndpointData& data);

/// Odometry with `params` from the first ground-truth pose to the last sample
/// with ground truth, compared with ground truth there (start frame).
std::vector<ReturnError> ReturnErrorsFromTrajectories(const TrajectoryData& data, const RobotParams& params,
                                                      const RobotParams& recorded, Integrator integrator);

}  // namespace umbmark
