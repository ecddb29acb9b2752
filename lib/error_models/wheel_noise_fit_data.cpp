// Data files -> fit-noise runs; see wheel_noise_fit_data.hpp.
#include "error_models/wheel_noise_fit_data.hpp"

#include <cmath>
#include <limits>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "error_models/path_covariance.hpp"
#include "error_models/second_order.hpp"
#include "error_models/trajectory_covariance.hpp"
#include "kinematics/odometry.hpp"

namespace umbmark {

std::vector<WheelNoiseFitRun> NoiseRunsFromEndpoints(const EndpointData& data, const std::vector<PathSegment>& path,
                                                double wheelbase_m, const std::string& group_prefix,
                                                const NoiseFitInputOptions& options) {
  const std::vector<WheelSegment> wheels = ToWheelSegments(path, wheelbase_m);
  const PathCovarianceSummary pc = PredictPathCovariance(wheels, wheelbase_m, WheelNoise{}, PoseCovariance::Zero());
  SecondOrderBasis q2;
  if (options.second_order) q2 = SecondOrderHeadingBasis(wheels, wheelbase_m);
  const PoseCovariance M = MeasurementCovariance(options.sigma_xy_m, options.sigma_theta_rad, pc.mean);
  std::vector<WheelNoiseFitRun> out;
  for (const ReturnError& r : data.runs) {
    WheelNoiseFitRun f;
    f.group = group_prefix + r.direction;
    f.run = r.run;
    f.has_theta = r.etheta_rad.has_value();
    f.error = Eigen::Vector3d(r.ex_m, r.ey_m, f.has_theta ? WrapAngle(*r.etheta_rad) : 0.0);
    f.basis = pc.motion;
    f.second_order = q2;
    f.measurement = M;
    out.push_back(f);
  }
  return out;
}

std::vector<WheelNoiseFitRun> NoiseRunsFromTrajectories(const TrajectoryData& data, const RobotParams& robot,
                                                   const std::string& group_prefix,
                                                   const NoiseFitInputOptions& options, int* skipped) {
  std::vector<WheelNoiseFitRun> out;
  int skip = 0;
  for (const TrajectoryRun& run : data.runs) {
    const std::size_t n = run.size();
    if (n < 2 || !run.HasGroundTruth(0) || !run.HasGroundTruth(n - 1)) {
      ++skip;
      continue;
    }
    WheelTravel travel;
    try {
      travel = ComputeWheelTravel(run, robot, robot);
    } catch (const InputError& e) {
      throw InputError(data.path, run.lines.empty() ? 0 : run.lines.front(), 0, e.message());
    }
    const TrajectoryCovarianceSummary kelly = TrajectoryCovariance(travel, robot.wheelbase_m);
    const Pose2& odo = kelly.poses.back();
    const Pose2 gt = RelativeTo(run.GroundTruth(0), run.GroundTruth(n - 1));  // contract: GT in its first frame
    WheelNoiseFitRun f;
    f.group = group_prefix + run.direction;
    f.run = run.run;
    f.error = Eigen::Vector3d(gt.x - odo.x, gt.y - odo.y, WrapAngle(gt.theta - odo.theta));
    f.basis = kelly.motion;
    if (options.second_order) f.second_order = SecondOrderHeadingBasis(travel, robot.wheelbase_m);
    f.measurement = MeasurementCovariance(options.sigma_xy_m, options.sigma_theta_rad, odo);
    out.push_back(f);
  }
  if (skipped) *skipped = skip;
  return out;
}

}  // namespace umbmark
