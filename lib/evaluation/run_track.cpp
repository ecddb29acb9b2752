// Odometry vs ground truth in the start frame (see run_track.hpp).
#include "evaluation/run_track.hpp"

#include <cmath>
#include <limits>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "kinematics/odometry.hpp"

namespace umbmark {

RunTrack TrackRun(const TrajectoryRun& run, const std::string& file, const RobotParams& params, const RobotParams& recorded,
                  Integrator integrator) {
  const std::size_t n = run.size();
  if (n == 0 || !run.HasGroundTruth(0)) {
    throw InputError(file, run.lines.empty() ? 0 : run.lines.front(), 0,
                     "run " + run.run + " has no ground truth at its first sample");
  }
  RunTrack track;
  WheelTravel travel;
  try {
    travel = ComputeWheelTravel(run, params, recorded);
  } catch (const InputError& e) {  // a fault of the robot for this file: name the file, not "<input>"
    throw InputError(file, run.lines.empty() ? 0 : run.lines.front(), 0, e.message());
  }
  track.odometry = IntegrateOdometry(travel, params.wheelbase_m, Pose2{}, integrator);
  track.ground_truth.resize(n);
  track.has_ground_truth.resize(n);
  const Pose2 world_T_start = run.GroundTruth(0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  double total = 0.0, prev_theta = world_T_start.theta;
  for (std::size_t i = 0; i < n; ++i) {
    if (!run.HasGroundTruth(i)) {
      track.ground_truth[i] = {nan, nan, nan};
      track.has_ground_truth[i] = false;
      continue;
    }
    const Pose2 world_T_i = run.GroundTruth(i);
    total += WrapAngle(world_T_i.theta - prev_theta);
    prev_theta = world_T_i.theta;
    Pose2 start_T_i = RelativeTo(world_T_start, world_T_i);
    start_T_i.theta = total;  // continuous heading relative to the start
    track.ground_truth[i] = start_T_i;
    track.has_ground_truth[i] = true;
    track.last_gt = i;
  }
  track.gt_total_rotation_rad = total;
  return track;
}

}  // namespace umbmark
