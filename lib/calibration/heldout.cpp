// Leave-one-run-out comparison of calibration methods (see heldout.hpp).
#include "calibration/heldout.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>

#include <Eigen/Core>
#include <Eigen/LU>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/fisher_f.hpp>
#include <fmt/format.h>

#include "core/errors.hpp"
#include "model/commanded_square.hpp"

namespace umbmark {

const MethodHeldout* HeldoutComparison::Find(const std::string& method) const {
  for (const auto& m : methods) {
    if (m.method == method) return &m;
  }
  return nullptr;
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Leave-one-run-out costs one calibration per run, time quadratic in the
/// runs; above this many runs the folds are kFolds interleaved groups of
/// runs instead (k-fold cross-validation over runs).
constexpr std::size_t kMaxLeaveOneOutRuns = 200;
constexpr std::size_t kFolds = 10;

/// The runs `keep` of `in`; their trajectories only when a method needs them.
CalibrateInput Subset(const CalibrateInput& in, const std::vector<std::size_t>& keep, bool with_trajectories) {
  CalibrateInput out;
  out.label = in.label;
  out.path = in.path;
  out.recorded = in.recorded;
  out.side_m = in.side_m;
  out.errors.reserve(keep.size());
  for (std::size_t i : keep) out.errors.push_back(in.errors[i]);
  if (in.trajectories && with_trajectories) {
    out.trajectories.emplace();
    out.trajectories->path = in.trajectories->path;
    out.trajectories->runs.reserve(keep.size());
    for (std::size_t i : keep) out.trajectories->runs.push_back(in.trajectories->runs[i]);
  }
  return out;
}

/// How well `p` predicts run i of `in` (see heldout.hpp) [m].
double PredictionError(const CalibrateInput& in, std::size_t i, const RobotParams& p, Integrator integrator,
                       bool final_turn) {
  if (in.trajectories) {
    return EvaluateRun(in.trajectories->runs[i], in.trajectories->path, in.label, p, in.recorded, integrator)
        .max_position_error_m;
  }
  const ReturnError& e = in.errors[i];
  const auto direction = SquareDirectionFromString(e.direction);
  if (!direction) throw InputError(in.path, e.line, 0, fmt::format("run {}: direction must be cw or ccw", e.run));
  const RobotParams& r = in.recorded;
  const Pose2 model = SquareReturnError(*direction, in.side_m, r.wheelbase_m, p.wheelbase_m / r.wheelbase_m,
                                        p.wheel_diameter_left_m / r.wheel_diameter_left_m,
                                        p.wheel_diameter_right_m / r.wheel_diameter_right_m, final_turn);
  return std::hypot(e.ex_m - model.x, e.ey_m - model.y);
}

UmbmarkOptions FoldUmbmarkOptions(const CalibrateInput& in, const CalibrateJobOptions& options,
                                  UmbmarkEstimator estimator) {
  UmbmarkOptions uo = options.umbmark;
  uo.side_m = in.side_m;
  uo.estimator = estimator;
  uo.exclude_runs.clear();  // decided once, on all runs
  uo.reject_outliers = false;
  return uo;
}

}  // namespace

HeldoutComparison CompareMethodsHeldout(const CalibrateInput& input, const CalibrateJobOptions& options,
                                        const CalibrateJobResult& full) {
  HeldoutComparison out;
  out.measure = input.trajectories ? "max_position_error_m" : "return_error_prediction_m";
  const bool final_turn = options.refine ? options.refine->final_turn : true;
  std::vector<std::size_t> used;
  for (std::size_t i = 0; i < full.umbmark.runs.size(); ++i) {
    if (full.umbmark.runs[i].used()) used.push_back(i);
  }
  const bool with_trajectories = options.refine.has_value();  // only the refined fits read them
  const CalibrateInput all_used = Subset(input, used, with_trajectories);
  const std::vector<bool> keep_all(used.size(), true);

  // A method: its parameters from a set of runs (throws when it cannot fit).
  using Fit = std::function<RobotParams(const CalibrateInput&)>;
  struct Method {
    std::string name;
    Fit fit;
  };
  std::vector<Method> methods;
  methods.push_back({"recorded", [](const CalibrateInput& in) { return in.recorded; }});
  for (UmbmarkEstimator est : {UmbmarkEstimator::kX, UmbmarkEstimator::kY, UmbmarkEstimator::kMean}) {
    methods.push_back({fmt::format("umbmark_{}", UmbmarkEstimatorToString(est)), [&, est](const CalibrateInput& in) {
                         return CalibrateUmbmark(in.errors, in.recorded, FoldUmbmarkOptions(in, options, est), in.path)
                             .corrected;
                       }});
  }
  auto refine_with = [&](const RefineOptions& ro) {
    return [&, ro](const CalibrateInput& in) {
      const UmbmarkSummary classic =
          CalibrateUmbmark(in.errors, in.recorded, FoldUmbmarkOptions(in, options, options.umbmark.estimator), in.path);
      return RefineInput(in, std::vector<bool>(in.errors.size(), true), ro, classic.selected, options.integrator)
          .refined;
    };
  };
  if (options.refine) {
    methods.push_back({"refined", refine_with(*options.refine)});
    if (input.trajectories) methods.push_back({"plain_least_squares", refine_with(PlainLeastSquaresOptions())});
  }

  // Parameters on all used runs.
  out.methods.resize(methods.size());
  for (std::size_t m = 0; m < methods.size(); ++m) {
    MethodHeldout& h = out.methods[m];
    h.method = methods[m].name;
    if (h.method == "refined" && full.refined) {
      h.parameters = full.refined->refined;
      continue;
    }
    try {
      h.parameters = methods[m].fit(all_used);
    } catch (const std::runtime_error& e) {  // InputError, QualityGateError
      h.failure = e.what();
      h.parameters = input.recorded;
    }
  }

  // Folds: each run alone, or kFolds interleaved groups (both directions in
  // each) for many runs; a fold's error is the mean over its runs.
  std::vector<std::vector<std::size_t>> folds;
  if (used.size() <= kMaxLeaveOneOutRuns) {
    for (std::size_t k = 0; k < used.size(); ++k) folds.push_back({k});
  } else {
    out.scheme = "k_fold_over_runs";
    folds.resize(kFolds);
    for (std::size_t k = 0; k < used.size(); ++k) folds[k % kFolds].push_back(k);
    out.notes.push_back(fmt::format("{} runs: {}-fold cross-validation over runs instead of leave-one-run-out",
                                    used.size(), kFolds));
  }
  std::vector<bool> complete;  // every method predicted this fold
  std::vector<bool> in_fold(used.size(), false);
  ProgressCounter progress(options.progress, static_cast<double>(folds.size()));
  for (std::size_t f = 0; f < folds.size(); ++f) {
    for (std::size_t k : folds[f]) in_fold[k] = true;
    std::vector<std::size_t> rest;
    rest.reserve(used.size());
    for (std::size_t j = 0; j < used.size(); ++j) {
      if (!in_fold[j]) rest.push_back(used[j]);
    }
    for (std::size_t k : folds[f]) in_fold[k] = false;
    const CalibrateInput train = Subset(input, rest, with_trajectories);
    out.left_out.push_back(folds[f].size() == 1
                               ? input.errors[used[folds[f].front()]].run
                               : fmt::format("fold {} of {} ({} runs)", f + 1, folds.size(), folds[f].size()));
    bool all = true;
    for (std::size_t m = 0; m < methods.size(); ++m) {
      double err = kNaN;
      try {
        const RobotParams p = methods[m].fit(train);
        double sum = 0.0;
        for (std::size_t k : folds[f]) sum += PredictionError(input, used[k], p, options.integrator, final_turn);
        err = sum / static_cast<double>(folds[f].size());
      } catch (const std::runtime_error& e) {  // InputError, QualityGateError
        if (out.methods[m].failure.empty()) out.methods[m].failure = e.what();
      }
      out.methods[m].fold_errors_m.push_back(err);
      all = all && std::isfinite(err);
    }
    complete.push_back(all);
    progress.Add();
  }
  int formed = 0;
  for (std::size_t k = 0; k < complete.size(); ++k) {
    // A fold where even the classic methods fail could not be formed (e.g. the
    // only run of a direction left out); it is not held against any method.
    const bool classic_ok = std::isfinite(out.methods[1].fold_errors_m[k]);
    if (!classic_ok) {
      out.notes.push_back(fmt::format("run {} cannot be left out (the rest does not calibrate)", out.left_out[k]));
      continue;
    }
    ++formed;
    for (auto& h : out.methods) h.failed_folds += std::isfinite(h.fold_errors_m[k]) ? 0 : 1;
  }
  for (auto& h : out.methods) {
    double sum = 0.0, sq = 0.0;
    int n = 0;
    for (std::size_t k = 0; k < complete.size(); ++k) {
      if (!complete[k]) continue;
      sum += h.fold_errors_m[k];
      sq += h.fold_errors_m[k] * h.fold_errors_m[k];
      ++n;
    }
    h.folds = n;
    h.mean_m = n > 0 ? sum / n : kNaN;
    h.rms_m = n > 0 ? std::sqrt(sq / n) : kNaN;
    double ss = 0.0;
    for (std::size_t k = 0; k < complete.size(); ++k) {
      if (complete[k]) ss += std::pow(h.fold_errors_m[k] - h.mean_m, 2);
    }
    h.sem_m = n > 1 ? std::sqrt(ss / (n - 1) / n) : kNaN;
    if (h.failed_folds > 0) {
      out.notes.push_back(fmt::format("{} failed on {} of {} folds (first: {}); it is not recommended", h.method,
                                      h.failed_folds, formed, h.failure));
    }
  }
  if (formed < 3 || out.methods.front().folds < 3) {
    out.notes.push_back(fmt::format("only {} leave-one-run-out folds: too few to recommend a method", formed));
    return out;
  }
  // Lowest mean among calibration methods that completed every fold.
  const MethodHeldout* best = nullptr;
  const MethodHeldout* second = nullptr;
  for (const auto& h : out.methods) {
    if (h.method == "recorded" || h.failed_folds > 0 || !std::isfinite(h.mean_m)) continue;
    if (!best || h.mean_m < best->mean_m) {
      second = best;
      best = &h;
    } else if (!second || h.mean_m < second->mean_m) {
      second = &h;
    }
  }
  if (!best) return out;
  out.recommended = best->method;
  if (second) {
    out.runner_up = second->method;
    std::vector<double> d;
    for (std::size_t k = 0; k < complete.size(); ++k) {
      if (complete[k]) d.push_back(second->fold_errors_m[k] - best->fold_errors_m[k]);
    }
    double mean = 0.0;
    for (double v : d) mean += v;
    mean /= static_cast<double>(d.size());
    double ss = 0.0;
    for (double v : d) ss += (v - mean) * (v - mean);
    out.runner_up_difference_m = mean;
    out.runner_up_difference_sem_m = d.size() > 1 ? std::sqrt(ss / static_cast<double>(d.size() - 1) /
                                                              static_cast<double>(d.size()))
                                                  : kNaN;
  }
  return out;
}

ModelCheck CheckCentresAgainstModel(const CalibrateInput& input, const std::vector<RunFlag>& flags,
                                    const RobotParams& p, bool final_turn) {
  ModelCheck out;
  double chi2 = 0.0;
  int groups = 0;
  for (const char* dir : {"cw", "ccw"}) {
    std::vector<Eigen::Vector2d> d;
    for (std::size_t i = 0; i < input.errors.size(); ++i) {
      const ReturnError& e = input.errors[i];
      if (e.direction != dir || !flags[i].used()) continue;
      const RobotParams& r = input.recorded;
      const Pose2 model = SquareReturnError(*SquareDirectionFromString(dir), input.side_m, r.wheelbase_m,
                                            p.wheelbase_m / r.wheelbase_m,
                                            p.wheel_diameter_left_m / r.wheel_diameter_left_m,
                                            p.wheel_diameter_right_m / r.wheel_diameter_right_m, final_turn);
      d.emplace_back(e.ex_m - model.x, e.ey_m - model.y);
    }
    const int n = static_cast<int>(d.size());
    if (n < 4) continue;
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& v : d) mean += v;
    mean /= n;
    Eigen::Matrix2d S = Eigen::Matrix2d::Zero();
    for (const auto& v : d) S += (v - mean) * (v - mean).transpose();
    S /= (n - 1);
    if (!(S.determinant() > 0.0)) continue;
    const double t2 = n * mean.dot(S.inverse() * mean);
    // T^2 (n - 2) / (2 (n - 1)) ~ F(2, n - 2) under the model.
    const double f = t2 * (n - 2) / (2.0 * (n - 1));
    const double upper = boost::math::cdf(boost::math::complement(boost::math::fisher_f(2.0, n - 2.0), f));
    // Its chi-square(2) equivalent: -2 log(upper) (exact for 2 dof).
    chi2 += -2.0 * std::log(std::max(upper, 1e-300));
    ++groups;
  }
  if (groups == 0) return out;
  out.available = true;
  out.dof = std::max(1, 2 * groups - 2);
  out.reduced_chi2 = chi2 / out.dof;
  out.p_value = boost::math::cdf(boost::math::complement(boost::math::chi_squared(out.dof), chi2));
  return out;
}

std::vector<std::string> TrustWarnings(const CalibrateJobResult& result, const HeldoutComparison& heldout,
                                       const ModelCheck& check) {
  std::vector<std::string> w;
  const auto& s = result.umbmark;
  if (s.cw.n < 4 || s.ccw.n < 4) {
    w.push_back(fmt::format(
        "the intervals and 3*SEM rest on {} cw and {} ccw runs: with fewer than 4 per direction they are "
        "optimistic (a 95 % interval covers the truth in about 81-90 % of campaigns); record 4-5 runs per direction",
        s.cw.n, s.ccw.n));
  }
  if (check.available && check.p_value < 0.01) {
    w.push_back(fmt::format(
        "the return errors' centres of gravity differ from the calibrated model by more than their scatter allows "
        "(reduced chi-square {:.2f} on {} dof, p = {:.2g}): the noise or error model is off (an effect the model "
        "lacks, such as turn scrub or a castor kick); run `umbmark diagnose` before trusting the correction",
        check.reduced_chi2, check.dof, check.p_value));
  }
  const MethodHeldout* rec = heldout.Find("recorded");
  const MethodHeldout* best = heldout.recommended.empty() ? nullptr : heldout.Find(heldout.recommended);
  if (rec && best && rec->mean_m < best->mean_m) {
    w.push_back(fmt::format(
        "no calibration predicts left-out runs better than the recorded parameters ({:.2f} mm vs {:.2f} mm for {}): "
        "the systematic error is within the scatter; keep the recorded parameters or record more runs",
        rec->mean_m * 1e3, best->mean_m * 1e3, best->method));
  }
  return w;
}

}  // namespace umbmark
