// Held-out comparison of calibration methods and the recommendation (see
// heldout.hpp).
#include "calibration/heldout.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <tuple>
#include <utility>

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

/// A method: its parameters from a set of runs (throws when it cannot fit).
struct Method {
  std::string name;
  int simplicity = 0;
  std::function<RobotParams(const CalibrateInput&)> fit;
  bool fits_scale = false;  ///< MethodHeldout::fits_scale
};

/// Step 1: every method the input allows, simplest first (heldout.hpp).
std::vector<Method> MethodsFor(const CalibrateInput& input, const CalibrateJobOptions& options) {
  std::vector<Method> methods;
  methods.push_back({"recorded", 0, [](const CalibrateInput& in) { return in.recorded; }});
  for (UmbmarkEstimator est : {UmbmarkEstimator::kX, UmbmarkEstimator::kY, UmbmarkEstimator::kMean}) {
    methods.push_back({fmt::format("umbmark_{}", UmbmarkEstimatorToString(est)), 1, [&options, est](const CalibrateInput& in) {
                         return CalibrateUmbmark(in.errors, in.recorded, FoldUmbmarkOptions(in, options, est), in.path)
                             .corrected;
                       }});
  }
  auto refine_with = [&options](const RefineOptions& ro) {
    return [&options, ro](const CalibrateInput& in) {
      const UmbmarkSummary classic =
          CalibrateUmbmark(in.errors, in.recorded, FoldUmbmarkOptions(in, options, options.umbmark.estimator), in.path);
      return RefineInput(in, std::vector<bool>(in.errors.size(), true), ro, classic.selected, options.integrator)
          .refined;
    };
  };
  // The full-path fits need ground truth along the path; there they are
  // compared without --refine too.
  const bool paths = input.trajectories && HasInteriorGroundTruth(*input.trajectories);
  if (paths) methods.push_back({"plain_least_squares", 2, refine_with(PlainLeastSquaresOptions()), true});
  if (options.refine || paths) {
    const RefineOptions ro = options.refine.value_or(options.compare_refine);
    const bool scale = ro.scale == ScaleMode::kFree || (paths && ro.scale == ScaleMode::kAuto);
    methods.push_back({"refined", 3, refine_with(ro), scale});
  }
  return methods;
}

/// One training set and what it predicts: each entry of `tests` is one fold
/// (its error the mean over its items).
struct TestItem {
  bool unseen = false;    ///< an unseen path (input.unseen) rather than a square run
  std::size_t file = 0;   ///< unseen: which TrajectoryData
  std::size_t index = 0;  ///< square: index into input.errors; unseen: run index
};
struct FoldGroup {
  std::vector<std::size_t> train;  ///< indices into input.errors
  std::vector<std::vector<TestItem>> tests;
  std::vector<std::string> labels;  ///< one per test
};

/// Step 2: the folds (scheme in heldout.hpp); sets out->scheme, sessions,
/// measure.
std::vector<FoldGroup> MakeFolds(const CalibrateInput& input, const std::vector<std::size_t>& used,
                                 HeldoutComparison* out) {
  std::vector<FoldGroup> groups;
  std::vector<int> session_ids;
  for (std::size_t i : used) session_ids.push_back(input.sessions.empty() ? 0 : input.sessions[i]);
  std::vector<int> distinct = session_ids;
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  out->sessions = static_cast<int>(distinct.size());
  std::size_t unseen_runs = 0;
  for (const auto& d : input.unseen) unseen_runs += d.runs.size();
  if (unseen_runs > 0) {
    out->scheme = "unseen_paths";
    out->measure = "final_position_error_m";
    FoldGroup g{used, {}, {}};
    for (std::size_t f = 0; f < input.unseen.size(); ++f) {
      for (std::size_t r = 0; r < input.unseen[f].runs.size(); ++r) {
        g.tests.push_back({{true, f, r}});
        g.labels.push_back(fmt::format("{}:{}", input.unseen[f].path, input.unseen[f].runs[r].run));
      }
    }
    groups.push_back(std::move(g));
    return groups;
  }
  if (distinct.size() >= 2) {
    out->scheme = "leave_one_session_out";
    for (int s : distinct) {
      FoldGroup g;
      for (std::size_t k = 0; k < used.size(); ++k) {
        if (session_ids[k] != s) {
          g.train.push_back(used[k]);
        } else {
          g.tests.push_back({{false, 0, used[k]}});
          g.labels.push_back(input.errors[used[k]].run);
        }
      }
      groups.push_back(std::move(g));
    }
    return groups;
  }
  const bool loo = used.size() <= kMaxLeaveOneOutRuns;
  if (!loo) {
    out->scheme = "k_fold_over_runs";
    out->notes.push_back(fmt::format("{} runs: {}-fold cross-validation over runs instead of leave-one-run-out",
                                     used.size(), kFolds));
  }
  const std::size_t n_folds = loo ? used.size() : kFolds;
  for (std::size_t f = 0; f < n_folds; ++f) {
    FoldGroup g;
    std::vector<TestItem> test;
    for (std::size_t k = 0; k < used.size(); ++k) {
      if (k % n_folds == f) {
        test.push_back({false, 0, used[k]});
      } else {
        g.train.push_back(used[k]);
      }
    }
    g.labels.push_back(test.size() == 1 ? input.errors[test.front().index].run
                                        : fmt::format("fold {} of {} ({} runs)", f + 1, n_folds, test.size()));
    g.tests.push_back(std::move(test));
    groups.push_back(std::move(g));
  }
  return groups;
}

/// How well `p` predicts one test item (see heldout.hpp) [m].
double ItemError(const CalibrateInput& in, const TestItem& t, const RobotParams& p, Integrator integrator,
                 bool final_turn) {
  if (t.unseen) {
    const TrajectoryData& d = in.unseen[t.file];
    return EvaluateRun(d.runs[t.index], d.path, in.label, p, in.recorded, integrator).final_position_error_m;
  }
  return PredictionError(in, t.index, p, integrator, final_turn);
}

/// Step 3: every method on every fold group; appends one error per test
/// (NaN where the method failed). A group where even classic UMBmark cannot calibrate the
/// training runs (e.g. the only run of a direction left out) is not formed.
void RunFolds(const CalibrateInput& input, const CalibrateJobOptions& options, const std::vector<Method>& methods,
              const std::vector<FoldGroup>& groups, bool with_trajectories, HeldoutComparison* out) {
  const bool final_turn = options.refine ? options.refine->final_turn : true;
  ProgressCounter progress(options.progress, static_cast<double>(groups.size()));
  for (const FoldGroup& g : groups) {
    const CalibrateInput train = Subset(input, g.train, with_trajectories);
    std::vector<std::vector<double>> errs(methods.size());  // [method][test]
    for (std::size_t m = 0; m < methods.size(); ++m) {
      errs[m].assign(g.tests.size(), kNaN);
      try {
        const RobotParams p = methods[m].fit(train);
        for (std::size_t t = 0; t < g.tests.size(); ++t) {
          double sum = 0.0;
          for (const TestItem& item : g.tests[t]) sum += ItemError(input, item, p, options.integrator, final_turn);
          errs[m][t] = sum / static_cast<double>(g.tests[t].size());
        }
      } catch (const std::runtime_error& e) {  // InputError, QualityGateError
        if (out->methods[m].failure.empty()) out->methods[m].failure = e.what();
      }
    }
    const bool formed = std::isfinite(errs[1].empty() ? kNaN : errs[1].front());  // classic (umbmark_x)
    for (std::size_t t = 0; t < g.tests.size(); ++t) {
      if (!formed) {
        out->notes.push_back(fmt::format("{} cannot be left out (the rest does not calibrate)", g.labels[t]));
        continue;
      }
      for (std::size_t m = 0; m < methods.size(); ++m) {
        out->methods[m].fold_errors_m.push_back(errs[m][t]);
      }
      out->left_out.push_back(g.labels[t]);
    }
    progress.Add();
  }
}

/// Mean and standard error of `v` over the complete folds.
std::pair<double, double> MeanAndSem(const std::vector<double>& v, const std::vector<bool>& complete) {
  double sum = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < complete.size(); ++k) {
    if (!complete[k]) continue;
    sum += v[k];
    ++n;
  }
  if (n == 0) return {kNaN, kNaN};
  const double mean = sum / n;
  double ss = 0.0;
  for (std::size_t k = 0; k < complete.size(); ++k) {
    if (complete[k]) ss += (v[k] - mean) * (v[k] - mean);
  }
  return {mean, n > 1 ? std::sqrt(ss / (n - 1) / n) : kNaN};
}

/// Mean and standard error of b - a over the complete folds.
std::pair<double, double> PairedDifference(const MethodHeldout& a, const MethodHeldout& b,
                                           const std::vector<bool>& complete) {
  std::vector<double> d(complete.size(), 0.0);
  for (std::size_t k = 0; k < complete.size(); ++k) {
    if (complete[k]) d[k] = b.fold_errors_m[k] - a.fold_errors_m[k];
  }
  return MeanAndSem(d, complete);
}

/// Step 4: each method's mean, SE and rms over the folds every method
/// completed.
void SummariseMethods(const std::vector<bool>& complete, HeldoutComparison* out) {
  const int formed = static_cast<int>(complete.size());
  for (auto& h : out->methods) {
    std::tie(h.mean_m, h.sem_m) = MeanAndSem(h.fold_errors_m, complete);
    double sq = 0.0;
    int n = 0;
    for (std::size_t k = 0; k < complete.size(); ++k) {
      if (!complete[k]) continue;
      sq += h.fold_errors_m[k] * h.fold_errors_m[k];
      ++n;
    }
    h.folds = n;
    h.rms_m = n > 0 ? std::sqrt(sq / n) : kNaN;
    if (h.failed_folds > 0) {
      out->notes.push_back(fmt::format("{} failed on {} of {} folds (first: {}); it is not recommended", h.method,
                                       h.failed_folds, formed, h.failure));
    } else if (!h.fitted_all) {
      out->notes.push_back(fmt::format("{} failed on all runs ({}); it is not recommended", h.method, h.failure));
    }
  }
}

/// Step 5a: the baseline, the simplest well-determined calibration
/// (heldout.hpp): plain least squares, else another full-path fit that
/// measures the scale, else the classic estimator asked for.
const MethodHeldout* Baseline(const CalibrateJobOptions& options, HeldoutComparison* out) {
  const MethodHeldout* plain = out->Find("plain_least_squares");
  if (plain && plain->Recommendable()) return plain;
  const MethodHeldout* scaled = nullptr;
  for (const auto& h : out->methods) {
    if (h.fits_scale && h.Recommendable() && (!scaled || h.simplicity < scaled->simplicity)) scaled = &h;
  }
  if (scaled) {
    out->notes.push_back(fmt::format("plain least squares is not well determined here; {} measures the overall scale "
                                     "too and is the baseline",
                                     scaled->method));
    return scaled;
  }
  const MethodHeldout* classic = out->Find(fmt::format("umbmark_{}", UmbmarkEstimatorToString(options.umbmark.estimator)));
  return classic ? classic : out->Find("recorded");
}

/// Step 5b: what the held-out runs could and could not test (heldout.hpp).
void DescribeChecks(const HeldoutComparison& h, const MethodHeldout& baseline, std::vector<std::string>* checked,
                    std::vector<std::string>* not_checked) {
  const bool other_shapes = h.scheme == "unseen_paths", other_sessions = h.scheme == "leave_one_session_out";
  if (other_shapes) {
    checked->push_back("paths of other shapes than the calibration runs, the overall scale (mean wheel diameter) "
                       "included: they do not close on themselves");
  } else if (other_sessions) {
    checked->push_back(fmt::format("other recording sessions ({}) of the same shape: what changes between sessions "
                                   "(floor, tyres, the ground truth's frame)",
                                   h.sessions));
  } else {
    checked->push_back("the run-to-run scatter of one recording session of one shape (in-distribution)");
  }
  if (!other_shapes) {
    not_checked->push_back(
        baseline.fits_scale
            ? "other shapes: squares close on themselves, so the overall scale (mean wheel diameter) hardly shows "
              "in them and what holding it at the recorded value costs on circles and free paths does not; "
              "methods that hold it (recorded, classic UMBmark) are therefore not recommended over one that "
              "measures it"
            : "the overall scale: no method compared here measures it (a square's return errors do not determine "
              "it); measure the mean wheel diameter another way, or record the path with ground truth along it");
  }
  if (!other_shapes && !other_sessions) {
    not_checked->push_back("other days or sessions: record squares in another session, or circles or free paths, "
                           "and give them in a manifest to check the choice on them");
  }
  if (other_shapes && h.sessions < 2) {
    not_checked->push_back("other days, unless the unseen paths were recorded on another day than the squares");
  }
}

/// Step 5: the recommendation rule (heldout.hpp).
void Recommend(const CalibrateJobOptions& options, const std::vector<bool>& complete, HeldoutComparison* out) {
  const MethodHeldout* baseline = Baseline(options, out);
  // A comparison that cannot see the overall scale (held-out runs of the
  // calibration's own shape) must not prefer a method holding it over a
  // baseline that measures it; one session of one shape is no evidence
  // that another full-path fit predicts other days better.
  const bool scale_unchecked = out->scheme != "unseen_paths";
  const bool held_scale_excluded = baseline->fits_scale && scale_unchecked;
  const bool in_distribution = out->scheme == "leave_one_run_out" || out->scheme == "k_fold_over_runs";
  DescribeChecks(*out, *baseline, &out->checked, &out->not_checked);
  out->baseline = baseline->method;
  const MethodHeldout* chosen = baseline;
  const int folds = out->methods.front().folds;
  // May `h` displace the baseline at all?
  auto eligible = [&](const MethodHeldout& h) {
    if (h.method == "recorded") return !held_scale_excluded;
    return h.Recommendable() && h.simplicity >= baseline->simplicity && (h.fits_scale || !held_scale_excluded);
  };
  if (folds < 3) {
    out->notes.push_back(fmt::format("only {} folds: too few to compare the methods; the simplest well-determined "
                                     "calibration ({}) is recommended",
                                     folds, baseline->method));
    out->why = "too few folds to compare: the simplest well-determined calibration";
  } else {
    const MethodHeldout* best = nullptr;
    for (const auto& h : out->methods) {
      if (h.method != "recorded" && eligible(h) && (!best || h.mean_m < best->mean_m)) best = &h;
    }
    out->why = fmt::format("the simplest well-determined calibration ({})", baseline->method);
    if (best && best != baseline) {
      if (!baseline->Recommendable()) {
        chosen = best;
        out->why = "lowest held-out error (the simplest well-determined calibration failed)";
      } else {
        const auto [d, se] = PairedDifference(*best, *baseline, complete);
        if (in_distribution && baseline->simplicity >= 2) {
          out->why = fmt::format("the plain, well-determined full-path fit; {} is {:.2f} mm +- {:.2f} (SE) lower on "
                                 "left-out runs of the same session and shape, which is no evidence for other days "
                                 "or shapes",
                                 best->method, d * 1e3, se * 1e3);
        } else if (d > se) {
          chosen = best;
          out->why = fmt::format("lowest held-out error, {:.2f} mm +- {:.2f} (SE) below {}", d * 1e3, se * 1e3,
                                 baseline->method);
        } else {
          out->why = fmt::format("the simplest well-determined calibration; {} is {:.2f} mm +- {:.2f} (SE) lower, "
                                 "within its standard error",
                                 best->method, d * 1e3, se * 1e3);
        }
      }
    }
    const MethodHeldout* rec = out->Find("recorded");
    if (eligible(*rec) && rec->folds > 0 && (!chosen->Recommendable() || rec->mean_m <= chosen->mean_m)) {
      chosen = rec;
      out->why = "the recorded parameters have the lowest held-out error: no calibration predicts unseen runs better";
    }
  }
  out->recommended = chosen->method;
  out->expected_error_m = chosen->mean_m;
  out->expected_error_sem_m = chosen->sem_m;
  // Runner-up: the lowest other method that could be recommended.
  const MethodHeldout* second = nullptr;
  for (const auto& h : out->methods) {
    if (&h != chosen && eligible(h) && h.folds > 0 && (!second || h.mean_m < second->mean_m)) second = &h;
  }
  if (second && chosen->folds > 0) {
    out->runner_up = second->method;
    std::tie(out->runner_up_difference_m, out->runner_up_difference_sem_m) =
        PairedDifference(*chosen, *second, complete);
  }
}

}  // namespace

// The named steps above: methods, folds, fits per fold, summary, rule.
HeldoutComparison CompareMethodsHeldout(const CalibrateInput& input, const CalibrateJobOptions& options,
                                        const CalibrateJobResult& full) {
  HeldoutComparison out;
  out.measure = input.trajectories ? "max_position_error_m" : "return_error_prediction_m";
  std::vector<std::size_t> used;
  for (std::size_t i = 0; i < full.umbmark.runs.size(); ++i) {
    if (full.umbmark.runs[i].used()) used.push_back(i);
  }
  const std::vector<Method> methods = MethodsFor(input, options);
  const bool with_trajectories = methods.back().simplicity >= 2;  // only the fits of the path read them
  const CalibrateInput all_used = Subset(input, used, with_trajectories);

  // Parameters on all used runs.
  out.methods.resize(methods.size());
  for (std::size_t m = 0; m < methods.size(); ++m) {
    MethodHeldout& h = out.methods[m];
    h.method = methods[m].name;
    h.simplicity = methods[m].simplicity;
    h.fits_scale = methods[m].fits_scale;
    if (h.method == "refined" && full.refined) {
      h.parameters = full.refined->refined;
      continue;
    }
    try {
      h.parameters = methods[m].fit(all_used);
    } catch (const std::runtime_error& e) {  // InputError, QualityGateError
      h.failure = e.what();
      h.parameters = input.recorded;
      h.fitted_all = false;
    }
  }
  const std::vector<FoldGroup> groups = MakeFolds(input, used, &out);
  RunFolds(input, options, methods, groups, with_trajectories, &out);
  RecommendFromFolds(options, &out);
  return out;
}

void RecommendFromFolds(const CalibrateJobOptions& options, HeldoutComparison* out) {
  if (out->methods.empty() || !out->Find("recorded")) throw InvalidOptions("RecommendFromFolds: no recorded method");
  const std::size_t folds = out->methods.front().fold_errors_m.size();
  std::vector<bool> complete(folds, true);
  for (auto& m : out->methods) {
    if (m.fold_errors_m.size() != folds) throw InvalidOptions("RecommendFromFolds: methods differ in their folds");
    m.failed_folds = 0;
    for (std::size_t k = 0; k < folds; ++k) {
      const bool ok = std::isfinite(m.fold_errors_m[k]);
      complete[k] = complete[k] && ok;
      m.failed_folds += ok ? 0 : 1;
    }
  }
  SummariseMethods(complete, out);
  Recommend(options, complete, out);
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
  const MethodHeldout* best = nullptr;  // the lowest calibration
  for (const auto& h : heldout.methods) {
    if (h.method != "recorded" && h.Recommendable() && (!best || h.mean_m < best->mean_m)) best = &h;
  }
  if (rec && best && rec->folds > 0 && rec->mean_m <= best->mean_m) {
    w.push_back(fmt::format(
        "no calibration predicts left-out runs better than the recorded parameters ({:.2f} mm vs {:.2f} mm for {}): "
        "the systematic error is within the scatter; keep the recorded parameters or record more runs",
        rec->mean_m * 1e3, best->mean_m * 1e3, best->method));
  }
  return w;
}

}  // namespace umbmark
