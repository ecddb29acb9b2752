// Evaluation measures along trajectories (see trajectory_eval.hpp).
#include "evaluation/trajectory_eval.hpp"

#include <algorithm>
#include <cmath>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "evaluation/run_track.hpp"

namespace umbmark {

RunEvaluation EvaluateRun(const TrajectoryRun& run, const std::string& file, const std::string& experiment,
                          const RobotParams& params, const RobotParams& recorded, Integrator integrator) {
  const RunTrack track = TrackRun(run, file, params, recorded, integrator);
  RunEvaluation ev;
  ev.experiment = experiment;
  ev.run = run.run;
  ev.direction = run.direction;
  for (std::size_t i = 0; i < run.size(); ++i) {
    if (!track.has_ground_truth[i]) continue;
    const Pose2& gt = track.ground_truth[i];
    const Pose2& odo = track.odometry[i];
    const double pos = std::hypot(gt.x - odo.x, gt.y - odo.y);
    const double head = std::abs(WrapAngle(gt.theta - odo.theta));
    ev.max_position_error_m = std::max(ev.max_position_error_m, pos);
    ev.max_heading_error_rad = std::max(ev.max_heading_error_rad, head);
  }
  const std::size_t k = track.last_gt;
  const Pose2& gt = track.ground_truth[k];
  const Pose2& odo = track.odometry[k];
  ev.final_position_error_m = std::hypot(gt.x - odo.x, gt.y - odo.y);
  ev.final_heading_error_rad = std::abs(WrapAngle(gt.theta - odo.theta));
  ev.return_error = {gt.x - odo.x, gt.y - odo.y, WrapAngle(gt.theta - odo.theta)};
  return ev;
}

std::vector<RunEvaluation> EvaluateRuns(const TrajectoryData& data, const std::string& experiment,
                                        const RobotParams& params, const RobotParams& recorded,
                                        Integrator integrator) {
  std::vector<RunEvaluation> out;
  out.reserve(data.runs.size());
  for (const auto& run : data.runs) out.push_back(EvaluateRun(run, data.path, experiment, params, recorded, integrator));
  return out;
}

EvaluationSummary Summarise(std::vector<RunEvaluation> runs) {
  EvaluationSummary s;
  s.runs = std::move(runs);
  if (s.runs.empty()) return s;
  const double n = static_cast<double>(s.runs.size());
  auto acc = [&](double RunEvaluation::*field, double& mean, double& max) {
    double sum = 0.0;
    for (const auto& r : s.runs) {
      sum += r.*field;
      max = std::max(max, r.*field);
    }
    mean = sum / n;
  };
  acc(&RunEvaluation::final_position_error_m, s.mean_final_position_error_m, s.max_final_position_error_m);
  acc(&RunEvaluation::max_position_error_m, s.mean_max_position_error_m, s.max_max_position_error_m);
  acc(&RunEvaluation::final_heading_error_rad, s.mean_final_heading_error_rad, s.max_final_heading_error_rad);
  acc(&RunEvaluation::max_heading_error_rad, s.mean_max_heading_error_rad, s.max_max_heading_error_rad);
  return s;
}

}  // namespace umbmark
