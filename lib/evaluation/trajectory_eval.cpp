// Evaluation measures along trajectories (see trajectory_eval.hpp).
#include "evaluation/trajectory_eval.hpp"

#include <algorithm>
#include <cmath>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "core/pose2.hpp"
#include "kinematics/diff_drive.hpp"

namespace umbmark {

namespace {
/// WrapAngle, skipping remainder() for an angle already in (-pi, pi] (then
/// remainder returns it unchanged, quotient 0): the common case here.
inline double Wrap(double a) { return a > -kPi && a <= kPi ? a : WrapAngle(a); }
}  // namespace

// One pass over the run, nothing stored per sample: the arithmetic of
// TrackRun (ComputeWheelTravel, IntegrateOdometry, RelativeTo the first
// ground-truth pose) in the same order, so every number is bit for bit
// TrackRun's (tests/test_evaluate_parts.cpp compares them), at a fraction of
// the cost: no allocation, and the start pose's inverse with its cosine and
// sine computed once per run instead of twice per sample (RelativeTo is
// Compose(Inverse(start), p)). `evaluate` spends most of its time here and in
// the reader.
RunEvaluation EvaluateRun(const TrajectoryRun& run, const std::string& file, const std::string& experiment,
                          const RobotParams& params, const RobotParams& recorded, Integrator integrator) {
  const std::size_t n = run.size();
  const auto fail = [&](const std::string& what) {
    throw InputError(file, run.lines.empty() ? 0 : run.lines.front(), 0, what);
  };
  if (n == 0 || !run.HasGroundTruth(0)) fail("run " + run.run + " has no ground truth at its first sample");
  const bool ticks = run.has_ticks();
  double kl = 0.0, kr = 0.0;  // metres per tick, or the diameter scale of dist_* (as ComputeWheelTravel)
  if (ticks) {
    if (auto err = params.CheckTicks(); !err.empty()) fail("run " + run.run + ": " + err);
    kl = params.MetresPerTickLeft();
    kr = params.MetresPerTickRight();
  } else {
    kl = params.wheel_diameter_left_m / recorded.wheel_diameter_left_m;
    kr = params.wheel_diameter_right_m / recorded.wheel_diameter_right_m;
  }
  const auto travel_left = [&](std::size_t i) {
    return ticks ? kl * static_cast<double>(run.ticks_left[i] - run.ticks_left[0])
                 : kl * (run.dist_left_m[i] - run.dist_left_m[0]);
  };
  const auto travel_right = [&](std::size_t i) {
    return ticks ? kr * static_cast<double>(run.ticks_right[i] - run.ticks_right[0])
                 : kr * (run.dist_right_m[i] - run.dist_right_m[0]);
  };
  const Pose2 world_T_start = run.GroundTruth(0);
  const Pose2 start_T_world = Inverse(world_T_start);
  const double c = std::cos(start_T_world.theta), s = std::sin(start_T_world.theta);
  RunEvaluation ev;
  ev.experiment = experiment;
  ev.run = run.run;
  ev.direction = run.direction;
  Pose2 odo{}, final_gt{}, final_odo{};
  double left = travel_left(0), right = travel_right(0);
  double total = 0.0, prev_theta = world_T_start.theta;
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0) {
      const double l = travel_left(i), r = travel_right(i);
      odo = DiffDriveStep(odo, l - left, r - right, params.wheelbase_m, integrator);
      left = l;
      right = r;
    }
    if (!run.HasGroundTruth(i)) continue;
    const Pose2 world_T_i = run.GroundTruth(i);
    total += Wrap(world_T_i.theta - prev_theta);
    prev_theta = world_T_i.theta;
    // Compose(start_T_world, world_T_i) with the continuous heading.
    const Pose2 gt{start_T_world.x + c * world_T_i.x - s * world_T_i.y,
                   start_T_world.y + s * world_T_i.x + c * world_T_i.y, total};
    const double pos = std::hypot(gt.x - odo.x, gt.y - odo.y);
    const double head = std::abs(Wrap(gt.theta - odo.theta));
    ev.max_position_error_m = std::max(ev.max_position_error_m, pos);
    ev.max_heading_error_rad = std::max(ev.max_heading_error_rad, head);
    final_gt = gt;
    final_odo = odo;
  }
  ev.final_position_error_m = std::hypot(final_gt.x - final_odo.x, final_gt.y - final_odo.y);
  ev.final_heading_error_rad = std::abs(Wrap(final_gt.theta - final_odo.theta));
  ev.return_error = {final_gt.x - final_odo.x, final_gt.y - final_odo.y, Wrap(final_gt.theta - final_odo.theta)};
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
