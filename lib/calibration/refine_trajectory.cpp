// Refined calibration from trajectories with ground truth (see refine.hpp):
// odometry from the encoder samples under theta vs ground truth in each
// run's start frame, at sampled poses.
//
// Sampling: options.samples_per_run poses per run, at equal steps of the
// run's travelled distance sum (|dL| + |dR|) / 2 (so a spot turn, where the
// centre does not move, is still sampled, and a standstill is not), each
// snapped forward to the next sample with ground truth; the last sample with
// ground truth is always included. A fixed count per run makes every run
// weigh the same, however long.
//
// Wheel travel is converted with the reference diameters (and each set's
// ticks_per_rev), so sets recorded with different parameters share one
// true robot: true travel = c * travel under the reference.
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <memory>

#include <ceres/covariance.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <fmt/format.h>

#include "calibration/refine.hpp"
#include "calibration/refine_internal.hpp"
#include "calibration/refine_residuals.hpp"
#include "evaluation/run_track.hpp"
#include "kinematics/odometry.hpp"

namespace umbmark {

namespace {

struct PreparedRun {
  std::vector<double> d_left_m, d_right_m;
  std::vector<TrajectoryRunResidual::Sample> samples;
  std::size_t set = 0;  ///< its TrajectoryRunSet (one recording session)
};

PreparedRun PrepareRun(const TrajectoryRun& run, const std::string& path, const RobotParams& conversion,
                       const RobotParams& recorded, const RefineOptions& options) {
  const RunTrack track = TrackRun(run, path, conversion, recorded, options.integrator);
  const WheelTravel travel = ComputeWheelTravel(run, conversion, recorded);
  for (std::size_t i = 0; i < run.size(); ++i) {
    if (!std::isfinite(travel.left_m[i]) || !std::isfinite(travel.right_m[i])) {
      throw InputError(path, run.lines.empty() ? 0 : run.lines[i], 0,
                       fmt::format("run {}: wheel travel is not finite", run.run));
    }
  }
  PreparedRun out;
  const std::size_t last = track.last_gt;
  if (last == 0) return out;
  // Cumulative travelled distance per sample.
  std::vector<double> s(last + 1, 0.0);
  for (std::size_t i = 1; i <= last; ++i) {
    s[i] = s[i - 1] + 0.5 * (std::abs(travel.left_m[i] - travel.left_m[i - 1]) +
                             std::abs(travel.right_m[i] - travel.right_m[i - 1]));
  }
  std::vector<std::size_t> picks;
  if (options.sampling == PoseSampling::kEverySample) {
    for (std::size_t k = 1; k <= last; ++k) {
      if (track.has_ground_truth[k]) picks.push_back(k);
    }
  } else {
    const int n = options.samples_per_run;
    std::size_t i = 1;
    for (int j = 1; j <= n && s[last] > 0.0; ++j) {
      const double target = s[last] * j / n;
      while (i < last && (s[i] < target || !track.has_ground_truth[i])) ++i;
      if (picks.empty() || picks.back() < i) picks.push_back(i);
    }
    if (picks.empty() || picks.back() != last) picks.push_back(last);
  }
  // Frame of the run: the first ground-truth sample, or the mean pose over
  // the initial standstill (samples before either wheel moves; the wheels
  // do not move there, so the odometry still starts at sample 0).
  Pose2 start{0.0, 0.0, 0.0};
  if (options.start_pose == StartPose::kStandstillMean) {
    double sx = 0.0, sy = 0.0, st = 0.0;
    int count = 0;
    for (std::size_t k = 0; k <= last && s[k] == 0.0; ++k) {
      if (!track.has_ground_truth[k]) continue;
      sx += track.ground_truth[k].x;
      sy += track.ground_truth[k].y;
      st += track.ground_truth[k].theta;  // continuous, near 0
      ++count;
    }
    start = {sx / count, sy / count, st / count};  // count >= 1: sample 0 has ground truth
  }
  for (std::size_t k : picks) {
    Pose2 g = RelativeTo(start, track.ground_truth[k]);
    g.theta = track.ground_truth[k].theta - start.theta;  // keep the heading continuous
    out.samples.push_back({k, g});
  }
  out.d_left_m.resize(last);
  out.d_right_m.resize(last);
  for (std::size_t k = 0; k < last; ++k) {
    out.d_left_m[k] = travel.left_m[k + 1] - travel.left_m[k];
    out.d_right_m[k] = travel.right_m[k + 1] - travel.right_m[k];
  }
  return out;
}

/// StartPose::kSessionFrame: one ground-truth frame error [yaw, o_x, o_y]
/// per set (session), fitted jointly with theta (both free, the scale as
/// `scale_free` says, same loss and weights) by Ceres; then every run's
/// samples are replaced by the corrected ones, so the fit that follows (and
/// its covariance) is conditional on the fitted frames. Notes say what was
/// fitted.
void FitSessionFrames(std::vector<PreparedRun>* prepared, std::size_t sets, const RobotParams& reference,
                      double heading_length, const RefineOptions& options, bool scale_free,
                      std::vector<std::string>* notes) {
  double theta[kNumRefineParameters] = {options.start.E_b, options.start.E_d, options.start.E_s};
  std::vector<std::array<double, 3>> frames(sets, {0.0, 0.0, 0.0});
  std::vector<int> runs_of(sets, 0);
  ceres::Problem problem;
  std::vector<std::shared_ptr<const TrajectoryRunResidual>> residuals;
  for (const PreparedRun& p : *prepared) {
    auto run = std::make_shared<const TrajectoryRunResidual>(p.d_left_m, p.d_right_m, reference.wheelbase_m,
                                                             p.samples, heading_length, options.loss,
                                                             options.loss_scale_m, options.integrator);
    problem.AddResidualBlock(TrajectoryRunResidual::CreateFramed(run), nullptr, theta, frames[p.set].data());
    residuals.push_back(std::move(run));
    ++runs_of[p.set];
  }
  if (!scale_free) problem.SetManifold(theta, new ceres::SubsetManifold(kNumRefineParameters, {kIndexEs}));
  const ceres::Solver::Options so = refine_detail::SolverOptions(options);
  ceres::Solver::Summary cs;
  ceres::Solve(so, &problem, &cs);
  if (!cs.IsSolutionUsable()) {
    notes->push_back("session frame error: the joint fit failed (" + cs.message + "); no frame error assumed");
    return;
  }
  for (std::size_t i = 0; i < prepared->size(); ++i) {
    (*prepared)[i].samples = residuals[i]->CorrectedSamples(frames[(*prepared)[i].set].data());
  }
  // Standard errors of each frame: Ceres' inverse information scaled by the
  // residual variance (the solver covariance: a guide, optimistic where
  // poses along a run are correlated; the parameters' intervals are the
  // run-clustered ones of the fit that follows, conditional on the frame).
  std::vector<std::array<double, 3>> se(sets, {0.0, 0.0, 0.0});
  ceres::Covariance covariance{ceres::Covariance::Options{}};
  std::vector<std::pair<const double*, const double*>> blocks;
  for (std::size_t s = 0; s < sets; ++s) {
    if (runs_of[s] > 0) blocks.emplace_back(frames[s].data(), frames[s].data());
  }
  const double dof = static_cast<double>(cs.num_residuals - cs.num_effective_parameters);
  const bool with_se = dof > 0.0 && covariance.Compute(blocks, &problem);
  for (std::size_t s = 0; with_se && s < sets; ++s) {
    double C[9];
    if (runs_of[s] == 0 || !covariance.GetCovarianceBlock(frames[s].data(), frames[s].data(), C)) continue;
    for (int i = 0; i < 3; ++i) se[s][static_cast<std::size_t>(i)] = std::sqrt(std::max(0.0, C[4 * i] * 2.0 * cs.final_cost / dof));
  }
  for (std::size_t s = 0; s < sets; ++s) {
    if (runs_of[s] == 0) continue;
    notes->push_back(fmt::format(
        "session frame error of set {} ({} runs), fitted jointly: ground-truth yaw {:+.2f} mrad, origin "
        "({:+.1f}, {:+.1f}) mm from the axle midpoint{}; the intervals below are conditional on it",
        s + 1, runs_of[s], frames[s][0] * 1e3, frames[s][1] * 1e3, frames[s][2] * 1e3,
        with_se ? fmt::format(" (solver standard errors {:.2f} mrad, {:.1f} and {:.1f} mm)", se[s][0] * 1e3,
                              se[s][1] * 1e3, se[s][2] * 1e3)
                : std::string()));
  }
}

/// Step 1: wheel travel and sampled ground truth of every run of every set
/// (notes and sampled_poses into *summary). Throws InputError when no run
/// has ground truth beyond its first sample.
std::vector<PreparedRun> PrepareSets(const std::vector<TrajectoryRunSet>& sets, const RobotParams& reference,
                                     const RefineOptions& options, RefineSummary* summary) {
  std::vector<PreparedRun> prepared;
  for (std::size_t si = 0; si < sets.size(); ++si) {
    const TrajectoryRunSet& set = sets[si];
    if (set.data == nullptr) throw InvalidOptions("TrajectoryRunSet::data is null");
    const std::string& path = set.data->path;
    if (auto e = set.recorded.Check(); !e.empty()) throw InputError(path, "recorded robot: " + e);
    RobotParams conversion = set.recorded;  // its ticks_per_rev, the reference diameters
    conversion.wheel_diameter_left_m = reference.wheel_diameter_left_m;
    conversion.wheel_diameter_right_m = reference.wheel_diameter_right_m;
    for (const TrajectoryRun& run : set.data->runs) {
      PreparedRun p = PrepareRun(run, path, conversion, set.recorded, options);
      if (p.samples.empty()) {
        summary->notes.push_back(fmt::format("{}: run {} skipped (ground truth at its first sample only)", path,
                                            run.run));
        continue;
      }
      summary->sampled_poses += static_cast<int>(p.samples.size());
      p.set = si;
      prepared.push_back(std::move(p));
    }
  }
  if (prepared.empty()) {
    throw InputError(sets.empty() || !sets.front().data ? "" : sets.front().data->path,
                     "no trajectory run with ground truth beyond its first sample to refine");
  }
  return prepared;
}

}  // namespace

RefineSummary RefineFromTrajectories(const std::vector<TrajectoryRunSet>& sets, const RobotParams& reference,
                                     const RefineOptions& options) {
  using refine_detail::CovarianceKind;
  using refine_detail::FitProblem;
  if (auto e = options.Check(); !e.empty()) throw InvalidOptions(e);
  if (auto e = reference.Check(); !e.empty()) throw InvalidOptions("reference robot: " + e);

  // ---- step 1: wheel travel and sampled ground truth per run ----
  RefineSummary summary;
  summary.input = RefineInputKind::kTrajectories;
  summary.reference = reference;
  std::vector<PreparedRun> prepared = PrepareSets(sets, reference, options, &summary);
  summary.runs = static_cast<int>(prepared.size());
  const double heading_length =
      options.heading_weight * (options.heading_length_m > 0.0 ? options.heading_length_m : reference.wheelbase_m);
  const bool fit_start = options.start_pose == StartPose::kFitted;
  summary.trajectory_settings = {PoseSamplingToString(options.sampling), StartPoseToString(options.start_pose),
                                 RobustLossToString(options.loss), heading_length, options.loss_scale_m};

  // ---- step 2: build, solve and assess (E_s free unless fixed) ----
  const std::vector<PreparedRun> as_recorded = prepared;
  auto attempt = [&](bool scale_free) {
    std::vector<std::string> frame_notes;
    if (options.start_pose == StartPose::kSessionFrame) {
      prepared = as_recorded;
      FitSessionFrames(&prepared, sets.size(), reference, heading_length, options, scale_free, &frame_notes);
    }
    FitProblem fit;
    fit.theta[kIndexEb] = options.start.E_b;
    fit.theta[kIndexEd] = options.start.E_d;
    fit.theta[kIndexEs] = options.start.E_s;
    fit.scale_free = scale_free;
    for (const PreparedRun& p : prepared) {
      ceres::CostFunction* cost =
          TrajectoryRunResidual::Create(p.d_left_m, p.d_right_m, reference.wheelbase_m, p.samples, heading_length,
                                        options.loss, options.loss_scale_m, options.integrator, fit_start);
      fit.problem->AddResidualBlock(cost, nullptr, fit.theta);
      fit.blocks.push_back(cost);
      if (options.loss != RobustLoss::kNone) {
        fit.plain_blocks.emplace_back(TrajectoryRunResidual::Create(p.d_left_m, p.d_right_m, reference.wheelbase_m,
                                                                    p.samples, heading_length, RobustLoss::kNone,
                                                                    options.loss_scale_m, options.integrator, fit_start));
      }
    }
    fit.loss = options.loss;
    fit.loss_scale_m = options.loss_scale_m;
    const int p = scale_free ? 3 : 2;
    RefineSummary s = summary;
    s.notes.insert(s.notes.end(), frame_notes.begin(), frame_notes.end());
    CovarianceKind kind = CovarianceKind::kSolverScaled;
    std::optional<double> dof;
    if (options.covariance == TrajectoryCovariance::kRunClustered) {
      if (summary.runs >= p + 1) {
        kind = CovarianceKind::kRunClustered;
        dof = summary.runs - 1;
      } else {
        s.notes.push_back(fmt::format(
            "only {} runs: the run-clustered covariance needs at least {}, so the solver covariance scaled by the "
            "residual variance is reported; it is OPTIMISTIC (poses along a run are correlated): record more runs",
            summary.runs, p + 1));
      }
    }
    refine_detail::SolveAndAssess(fit, options, kind, dof, &s);
    return s;
  };

  if (options.scale == ScaleMode::kFixed) return attempt(false);
  if (options.scale == ScaleMode::kFree) return attempt(true);
  try {
    return attempt(true);
  } catch (const RefineError& err) {
    const auto& und = err.summary().identifiability.undetermined;
    const bool scale_weak = std::find(und.begin(), und.end(), "E_s") != und.end();
    if (!scale_weak) throw;
    summary.notes.push_back(fmt::format(
        "overall scale E_s held at {} (scale auto): with it free the fit reported: {}", options.start.E_s,
        err.summary().identifiability.message));
    return attempt(false);
  }
}

}  // namespace umbmark
