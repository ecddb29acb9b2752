// Evaluation measures of odometry against ground truth along trajectories
// (the OptiOdom paper's measures): per run the max and final position error
// and the max and final |heading error|; over runs their mean and max.
#pragma once

#include <string>
#include <vector>

#include "core/robot.hpp"
#include "core/runs.hpp"
#include "kinematics/diff_drive.hpp"
#include "core/pose2.hpp"

namespace umbmark {

struct RunEvaluation {
  std::string experiment;  ///< experiment label (file or manifest entry)
  std::string run;
  std::string direction;
  double final_position_error_m = 0.0;
  double max_position_error_m = 0.0;
  double final_heading_error_rad = 0.0;  ///< magnitude, wrapped
  double max_heading_error_rad = 0.0;    ///< magnitude, wrapped
  Pose2 return_error;                    ///< signed e = gt - odometry at the last GT sample
};

struct EvaluationSummary {
  std::vector<RunEvaluation> runs;
  double mean_final_position_error_m = 0.0, max_final_position_error_m = 0.0;
  double mean_max_position_error_m = 0.0, max_max_position_error_m = 0.0;
  double mean_final_heading_error_rad = 0.0, max_final_heading_error_rad = 0.0;
  double mean_max_heading_error_rad = 0.0, max_max_heading_error_rad = 0.0;
};

/// Evaluates one run of the file `file` (named in messages) with odometry
/// parameters `params`. Throws InputError for a run without ground truth at
/// its start.
RunEvaluation EvaluateRun(const TrajectoryRun& run, const std::string& file, const std::string& experiment,
                          const RobotParams& params, const RobotParams& recorded, Integrator integrator);

/// Evaluates every run of `data` with odometry parameters `params`.
/// Throws InputError (naming data.path) for runs without ground truth at start.
std::vector<RunEvaluation> EvaluateRuns(const TrajectoryData& data, const std::string& experiment,
                                        const RobotParams& params, const RobotParams& recorded,
                                        Integrator integrator);

/// Mean and max of the four measures over `runs` (zeros when empty).
EvaluationSummary Summarise(std::vector<RunEvaluation> runs);

}  // namespace umbmark
