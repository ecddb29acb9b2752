// Dead reckoning along a logged trajectory (see odometry.hpp).
#include "kinematics/odometry.hpp"

#include "core/errors.hpp"

namespace umbmark {

WheelTravel ComputeWheelTravel(const TrajectoryRun& run, const RobotParams& robot, const RobotParams& recorded) {
  WheelTravel w;
  const std::size_t n = run.size();
  w.left_m.resize(n);
  w.right_m.resize(n);
  if (run.has_ticks()) {
    if (auto err = robot.CheckTicks(); !err.empty()) throw InputError("", "run " + run.run + ": " + err);
    const double kl = robot.MetresPerTickLeft(), kr = robot.MetresPerTickRight();
    for (std::size_t i = 0; i < n; ++i) {
      w.left_m[i] = kl * static_cast<double>(run.ticks_left[i] - run.ticks_left[0]);
      w.right_m[i] = kr * static_cast<double>(run.ticks_right[i] - run.ticks_right[0]);
    }
  } else {
    const double sl = robot.wheel_diameter_left_m / recorded.wheel_diameter_left_m;
    const double sr = robot.wheel_diameter_right_m / recorded.wheel_diameter_right_m;
    for (std::size_t i = 0; i < n; ++i) {
      w.left_m[i] = sl * (run.dist_left_m[i] - run.dist_left_m[0]);
      w.right_m[i] = sr * (run.dist_right_m[i] - run.dist_right_m[0]);
    }
  }
  return w;
}

std::vector<Pose2> IntegrateOdometry(const WheelTravel& travel, double wheelbase_m, const Pose2& start,
                                     Integrator integrator) {
  const std::size_t n = travel.left_m.size();
  std::vector<Pose2> poses(n);
  if (n == 0) return poses;
  poses[0] = start;
  for (std::size_t i = 1; i < n; ++i) {
    poses[i] = DiffDriveStep(poses[i - 1], travel.left_m[i] - travel.left_m[i - 1],
                             travel.right_m[i] - travel.right_m[i - 1], wheelbase_m, integrator);
  }
  return poses;
}

}  // namespace umbmark
