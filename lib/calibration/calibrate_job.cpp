// One `calibrate` job (see calibrate_job.hpp).
#include "calibration/calibrate_job.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include <fmt/format.h>

#include "core/angles.hpp"
#include "core/errors.hpp"

namespace umbmark {

CalibrateInput InputFromTrajectories(TrajectoryData data, const RobotParams& recorded, double side_m,
                                     Integrator integrator, const std::string& label) {
  CalibrateInput in;
  in.label = label;
  in.path = data.path;
  in.recorded = recorded;
  in.side_m = side_m;
  in.errors = ReturnErrorsFromTrajectories(data, recorded, recorded, integrator);
  for (const auto& e : in.errors) {
    if (!e.gt_total_rotation_rad || std::abs(*e.gt_total_rotation_rad) < kPi) continue;
    const char* gt_dir = *e.gt_total_rotation_rad < 0.0 ? "cw" : "ccw";
    if ((e.direction == "cw" || e.direction == "ccw") && e.direction != gt_dir) {
      throw InputError(data.path, e.line, 0,
                       fmt::format("run {} is labelled {} but its ground truth turns {:+.1f} deg ({})", e.run,
                                   e.direction, Rad2Deg(*e.gt_total_rotation_rad), gt_dir));
    }
  }
  in.files = {data.path};
  in.trajectories = std::move(data);
  return in;
}

CalibrateInput InputFromEndpoints(const EndpointData& data, const RobotParams& recorded, double side_m,
                                  const std::string& label) {
  CalibrateInput in;
  in.label = label;
  in.path = data.path;
  in.recorded = recorded;
  in.side_m = side_m;
  in.errors = ReturnErrorsFromEndpoints(data);
  in.files = {data.path};
  return in;
}

CalibrateInput PoolInputs(const std::vector<CalibrateInput>& parts, const std::vector<std::string>& tags,
                          const std::string& label) {
  if (parts.empty()) throw std::invalid_argument("PoolInputs: no parts");
  if (parts.size() == 1) {
    CalibrateInput one = parts.front();
    one.label = label;
    return one;
  }
  CalibrateInput pooled;
  pooled.label = label;
  pooled.path = parts.front().path;
  pooled.recorded = parts.front().recorded;
  pooled.side_m = parts.front().side_m;
  const bool all_trajectories =
      std::all_of(parts.begin(), parts.end(), [](const CalibrateInput& p) { return p.trajectories.has_value(); });
  if (all_trajectories) pooled.trajectories.emplace().path = pooled.path;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const CalibrateInput& p = parts[k];
    if (p.side_m != pooled.side_m) {
      throw InputError(label, fmt::format("square experiments {} and {} have different sides ({} m, {} m): one UMBmark "
                                          "calibration needs one side; calibrate them separately (--per-experiment)",
                                          tags.front(), tags[k], pooled.side_m, p.side_m));
    }
    if (p.recorded.wheelbase_m != pooled.recorded.wheelbase_m ||
        p.recorded.wheel_diameter_left_m != pooled.recorded.wheel_diameter_left_m ||
        p.recorded.wheel_diameter_right_m != pooled.recorded.wheel_diameter_right_m) {
      throw InputError(label, "the square experiments were recorded with different robot parameters; calibrate them "
                              "separately (--per-experiment)");
    }
    for (ReturnError e : p.errors) {
      e.run = tags[k] + ":" + e.run;
      pooled.errors.push_back(std::move(e));
      pooled.sessions.push_back(static_cast<int>(k));
    }
    if (all_trajectories) {
      for (TrajectoryRun r : p.trajectories->runs) {
        r.run = tags[k] + ":" + r.run;
        pooled.trajectories->runs.push_back(std::move(r));
      }
    }
    pooled.files.insert(pooled.files.end(), p.files.begin(), p.files.end());
  }
  pooled.unseen = parts.front().unseen;
  return pooled;
}


ClusterStats ClusterOfUsed(const std::vector<ReturnError>& errors, const std::vector<RunFlag>& flags,
                           const std::string& direction) {
  std::vector<std::pair<double, double>> used;
  for (std::size_t i = 0; i < errors.size(); ++i)
    if (errors[i].direction == direction && flags[i].used()) used.emplace_back(errors[i].ex_m, errors[i].ey_m);
  return ClusterOf(used);
}

RefineSummary RefineInput(const CalibrateInput& input, const std::vector<bool>& keep, RefineOptions ro,
                          const UmbmarkEstimate& start, Integrator integrator) {
  ro.integrator = integrator;
  ro.start.E_b = start.E_b;
  ro.start.E_d = start.E_d;
  // Path geometry needs ground truth along the path; with ground truth at
  // the first and last sample only (the contract's minimum) the return
  // errors are all the data say, so the commanded-square model fits them.
  if (input.trajectories && HasInteriorGroundTruth(*input.trajectories)) {
    // One set per recording session (each has its own ground-truth frame
    // error with StartPose::kSessionFrame).
    std::map<int, TrajectoryData> kept;
    for (std::size_t i = 0; i < input.trajectories->runs.size(); ++i) {
      if (!keep[i]) continue;
      TrajectoryData& d = kept[input.sessions.empty() ? 0 : input.sessions[i]];
      d.path = input.trajectories->path;
      d.runs.push_back(input.trajectories->runs[i]);
    }
    std::vector<TrajectoryRunSet> sets;
    for (const auto& [session, d] : kept) sets.push_back({input.recorded, &d});
    return RefineFromTrajectories(sets, input.recorded, ro);
  }
  SquareRunSet set;
  set.side_m = input.side_m;
  set.recorded = input.recorded;
  set.source = input.path;
  for (std::size_t i = 0; i < input.errors.size(); ++i)
    if (keep[i]) set.errors.push_back(input.errors[i]);
  return RefineFromReturnErrors({set}, input.recorded, ro);
}

bool HasInteriorGroundTruth(const TrajectoryData& data) {
  for (const auto& run : data.runs)
    for (std::size_t i = 1; i + 1 < run.size(); ++i)
      if (run.HasGroundTruth(i)) return true;
  return false;
}

CalibrateJobResult RunCalibrateJob(const CalibrateInput& input, const CalibrateJobOptions& options) {
  CalibrateJobResult r;
  r.label = input.label;
  r.path = input.path;
  UmbmarkOptions uo = options.umbmark;
  uo.side_m = input.side_m;
  r.umbmark = CalibrateUmbmark(input.errors, input.recorded, uo, input.path);
  if (input.trajectories) {
    AfterCorrection a;
    const auto& data = *input.trajectories;
    a.before = Summarise(EvaluateRuns(data, input.label, input.recorded, input.recorded, options.integrator));
    a.after = Summarise(EvaluateRuns(data, input.label, r.umbmark.corrected, input.recorded, options.integrator));
    const auto after_errors = ReturnErrorsFromTrajectories(data, r.umbmark.corrected, input.recorded, options.integrator);
    a.cw = ClusterOfUsed(after_errors, r.umbmark.runs, "cw");
    a.ccw = ClusterOfUsed(after_errors, r.umbmark.runs, "ccw");
    a.E_max_syst_m = std::max(a.cw.r_cg_m, a.ccw.r_cg_m);
    a.sem_m = std::max(a.cw.sem_m, a.ccw.sem_m);
    a.second_pass_worthwhile = a.E_max_syst_m > 3.0 * a.sem_m;
    r.evaluation = std::move(a);
  }
  if (options.refine) {
    std::vector<bool> keep;
    for (const auto& f : r.umbmark.runs) keep.push_back(f.used());
    try {
      r.refined = RefineInput(input, keep, *options.refine, r.umbmark.selected, options.integrator);
    } catch (const RefineError& e) {
      if (!options.keep_classic_on_refine_failure) throw;
      r.refine_failure = e;
      return r;
    }
    if (input.trajectories) {
      TrajectoryData kept;
      kept.path = input.trajectories->path;
      for (std::size_t i = 0; i < keep.size(); ++i)
        if (keep[i]) kept.runs.push_back(input.trajectories->runs[i]);
      r.refined_evaluation =
          Summarise(EvaluateRuns(kept, input.label, r.refined->refined, input.recorded, options.integrator));
    }
  }
  return r;
}

}  // namespace umbmark
