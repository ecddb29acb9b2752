// Return errors from endpoint files or trajectories (see return_error.hpp).
#include "evaluation/return_error.hpp"

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "evaluation/run_track.hpp"

namespace umbmark {

std::vector<ReturnError> ReturnErrorsFromEndpoints(const EndpointData& data) {
  std::vector<ReturnError> out = data.runs;
  for (ReturnError& e : out)
    if (e.etheta_rad) e.etheta_rad = WrapAngle(*e.etheta_rad);
  return out;
}

std::vector<ReturnError> ReturnErrorsFromTrajectories(const TrajectoryData& data, const RobotParams& params,
                                                      const RobotParams& recorded, Integrator integrator) {
  std::vector<ReturnError> out;
  out.reserve(data.runs.size());
  for (const auto& run : data.runs) {
    const RunTrack track = TrackRun(run, data.path, params, recorded, integrator);
    const std::size_t k = track.last_gt;
    const Pose2& gt = track.ground_truth[k];
    const Pose2& odo = track.odometry[k];
    ReturnError e;
    e.run = run.run;
    e.direction = run.direction;
    e.ex_m = gt.x - odo.x;
    e.ey_m = gt.y - odo.y;
    e.etheta_rad = WrapAngle(gt.theta - odo.theta);
    e.line = run.lines.empty() ? 0 : run.lines.front();
    e.gt_total_rotation_rad = track.gt_total_rotation_rad;
    out.push_back(std::move(e));
  }
  return out;
}

}  // namespace umbmark
