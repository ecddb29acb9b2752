// `umbmark calibrate` as a library call (see calibrate.hpp): the options'
// check, the loading of each input into calibration units, the fit with its
// plausibility gates, the held-out assessment, the parameters the outputs
// use, and the batch that records a failing unit and goes on.
#include "api/calibrate.hpp"

#include <algorithm>
#include <filesystem>
#include <initializer_list>
#include <set>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "api/calibrate_plot.hpp"
#include "calibration/plausibility.hpp"
#include "core/errors.hpp"
#include "formats/data_file.hpp"
#include "formats/manifest.hpp"
#include "formats/robot_id.hpp"
#include "output/output_set.hpp"
#include "planning/advice.hpp"

namespace umbmark::api {

namespace {

/// "--FLAG: V not in {a,b,c}" (the command line's message) unless `value` is one of `allowed`.
std::string OneOf(const char* flag, const std::string& value, std::initializer_list<const char*> allowed) {
  for (const char* a : allowed)
    if (value == a) return {};
  return fmt::format("{}: {} not in {{{}}}", flag, value, fmt::join(allowed, ","));
}

std::string NumberIn(const char* flag, double value, double lo, double hi) {
  if (std::isfinite(value) && value >= lo && value <= hi) return {};
  return fmt::format("{}: must be a number from {:g} to {:g} (got '{}')", flag, lo, hi, value);
}

std::string Positive(const char* flag, double value) {
  if (std::isfinite(value) && value > 0.0) return {};
  return fmt::format("{}: must be a finite number > 0 (got '{}')", flag, value);
}

bool Has(const std::vector<std::string>& v, const char* name) { return std::find(v.begin(), v.end(), name) != v.end(); }

}  // namespace

std::string CalibrateOptions::Check() const {
  if (inputs.empty() && data.empty()) return "DATA: give at least one endpoint or trajectory CSV, or manifest";
  for (const auto& path : inputs) {
    if (path.empty()) return "DATA: empty path; give a file name";
    if (path.find('\0') != std::string::npos) return "DATA: the path contains a NUL byte";
  }
  for (const auto& [flag, path] : {std::pair{"--ros2", &ros2}, {"--plot", &plot}, {"--report", &report}}) {
    if (path->find('\0') != std::string::npos) return fmt::format("{}: the path contains a NUL byte", flag);
  }
  if (std::string e = robot.Check(); !e.empty()) return e;
  if (side_m) {
    if (std::string e = CheckPlausibleFlag("--side", "side_m", *side_m); !e.empty()) return e;
  }
  for (const std::string& e :
       {OneOf("--estimator", estimator, {"x", "y", "mean"}), OneOf("--integrator", integrator, {"arc", "midpoint"}),
        OneOf("--ed-wheelbase", ed_wheelbase, {"corrected", "recorded"}),
        Positive("--outlier-threshold", outlier_threshold), OneOf("--loss", loss, {"huber", "cauchy", "none"}),
        Positive("--loss-scale", loss_scale_m), NumberIn("--samples-per-run", samples_per_run, 2, 100000),
        OneOf("--sampling", sampling, {"per_run", "every_sample"}),
        OneOf("--start-pose", start_pose, {"first_sample", "standstill_mean", "fitted", "session_frame"}),
        std::isfinite(heading_weight) && heading_weight >= 0.0
            ? std::string()
            : fmt::format("--heading-weight: must be a finite number >= 0 (got '{}')", heading_weight),
        OneOf("--use", use, {"recommended", "classic", "refined"}),
        scan_range_scale ? NumberIn("--scan-range-scale", *scan_range_scale, 0.5, 2.0) : std::string()}) {
    if (!e.empty()) return e;
  }
  for (const auto& f : fix)
    if (std::string e = OneOf("--fix", f, {"scale"}); !e.empty()) return e;
  for (const auto& f : free)
    if (std::string e = OneOf("--free", f, {"scale"}); !e.empty()) return e;
  if (Has(fix, "scale") && Has(free, "scale")) return "--fix scale and --free scale contradict each other";
  if (use == "refined" && !refine) return "--use refined needs --refine";
  return {};
}

namespace {

/// HeldoutComparison::scheme when no_heldout skipped the comparison.
constexpr const char* kHeldoutSkipped = "skipped";

/// The job options (RefineOptions checked: InvalidOptions).
CalibrateJobOptions JobOptions(const CalibrateOptions& o) {
  CalibrateJobOptions jo;
  jo.umbmark.estimator = *UmbmarkEstimatorFromString(o.estimator);
  jo.umbmark.ed_with_corrected_wheelbase = o.ed_wheelbase == "corrected";
  jo.umbmark.exclude_runs = o.exclude_runs;
  jo.umbmark.reject_outliers = o.reject_outliers;
  jo.umbmark.outlier_threshold = o.outlier_threshold;
  jo.integrator = *IntegratorFromString(o.integrator);
  jo.keep_classic_on_refine_failure = true;
  // The full-path fits' settings: used by refine and, without it, by the
  // held-out comparison on trajectory input (heldout.hpp).
  RefineOptions ro;
  if (Has(o.fix, "scale")) ro.scale = ScaleMode::kFixed;
  if (Has(o.free, "scale")) ro.scale = ScaleMode::kFree;
  ro.loss = *RobustLossFromString(o.loss);
  ro.loss_scale_m = o.loss_scale_m;
  ro.samples_per_run = o.samples_per_run;
  ro.sampling = *PoseSamplingFromString(o.sampling);
  ro.start_pose = *StartPoseFromString(o.start_pose);
  ro.heading_weight = o.heading_weight;
  if (auto err = ro.Check(); !err.empty()) throw InvalidOptions(err);
  jo.compare_refine = ro;
  if (o.refine) jo.refine = ro;
  return jo;
}

CalibrateInput FromRunFile(io::RunFile rf, const RobotParams& robot, double side, Integrator integrator,
                           const std::string& label) {
  if (auto* t = std::get_if<TrajectoryData>(&rf)) return InputFromTrajectories(std::move(*t), robot, side, integrator, label);
  return InputFromEndpoints(std::get<EndpointData>(rf), robot, side, label);
}

/// Runs of another shape with ground truth at the start and later (a final
/// error): held out for the comparison of methods.
void KeepUnseen(io::RunFile rf, std::vector<TrajectoryData>& unseen) {
  auto* t = std::get_if<TrajectoryData>(&rf);
  if (!t) return;
  std::erase_if(t->runs, [](const TrajectoryRun& r) {
    if (r.size() < 2 || !r.HasGroundTruth(0)) return true;
    for (std::size_t i = 1; i < r.size(); ++i)
      if (r.HasGroundTruth(i)) return false;
    return true;
  });
  if (!t->runs.empty()) unseen.push_back(std::move(*t));
}

// A manifest's square experiments pool into one calibration (one side
// length), or give one each with per_experiment.
std::vector<CalibrateInput> LoadManifest(const std::string& path, const CalibrateOptions& o, Integrator integrator) {
  std::vector<CalibrateInput> out;
  const Manifest m = io::ReadManifest(path);
  const RobotParams robot = o.robot.Resolve(m.robot);
  std::vector<std::string> tags;
  std::vector<TrajectoryData> unseen;
  int index = 0;
  for (const auto& e : m.experiments) {
    ++index;
    if (e.kind != ExperimentKind::kSquare) {
      KeepUnseen(io::ReadRunFile(e.resolved_file), unseen);
      continue;
    }
    const double side = o.side_m.value_or(e.side_m);
    out.push_back(FromRunFile(io::ReadRunFile(e.resolved_file), robot, side, integrator, fmt::format("{}#{}", path, index)));
    tags.push_back(std::to_string(index));
  }
  if (out.empty()) throw InputError(path, "the manifest has no square experiment to calibrate from");
  for (auto& in : out) in.unseen = unseen;
  if (!o.per_experiment && out.size() > 1) {
    return {PoolInputs(out, tags, fmt::format("{} (experiments {} pooled)", path, fmt::join(tags, ", ")))};
  }
  return out;
}

std::vector<CalibrateInput> LoadFile(const std::string& path, const CalibrateOptions& o, Integrator integrator) {
  if (io::IsManifestPath(path)) return LoadManifest(path, o, integrator);
  if (!o.side_m) throw InvalidOptions("--side S (square side in metres) is required for CSV input");
  return {FromRunFile(io::ReadRunFile(path), o.robot.Resolve(), *o.side_m, integrator, path)};
}

// The name a batch output is tagged with: the dataset, i.e. the input file's
// stem, or its folder when the file has a generic name (an import's
// campaign.toml / runs.csv), plus the experiment for per_experiment.
std::string DatasetTag(const std::string& input_path, const CalibrateInput& in) {
  const std::filesystem::path p(input_path);
  std::string stem = p.stem().string();
  if ((stem == "campaign" || stem == "runs") && p.has_parent_path() && !p.parent_path().filename().empty())
    stem = p.parent_path().filename().string();
  if (const auto hash = in.label.rfind('#'); hash != std::string::npos && in.label.find(' ', hash) == std::string::npos)
    stem += "-exp" + in.label.substr(hash + 1);
  return stem;
}

// The robot's id (formats/robot_id.hpp): from the robot file, else from the
// manifest the input came from ("M.toml#k"), else none.
std::string RobotIdOf(const CalibrateOptions& o, const CalibrateInput& in) {
  if (!o.robot.robot_file.empty()) return io::ReadRobotId(o.robot.robot_file);
  std::string path = in.label;
  if (const auto hash = path.rfind('#'); hash != std::string::npos &&
      path.find_first_not_of("0123456789", hash + 1) == std::string::npos && hash + 1 < path.size())
    path.resize(hash);
  return io::IsManifestPath(path) ? io::ReadRobotId(path) : std::string();
}

// Scan ground truth (a lidar's registration) carries the lidar's range
// scale: from scans alone only the wheels' ratio and the wheelbase relative
// to them are observable, not their overall scale. The classic estimate
// keeps the recorded scale; a method fitted to the scans' distances is
// rescaled by a stated range calibration (scan_range_scale), else to keep
// the recorded scale too (mean radius multiplier 1).
OutputsUse ScaleForScanGroundTruth(OutputsUse c, const std::string& ground_truth_source,
                                   std::optional<double> range_scale, const RobotParams& recorded) {
  const bool classic = c.method.rfind("umbmark_", 0) == 0 || c.method == "recorded";
  if (classic) {
    c.scale_source = "kept";
    c.scale_note = "the overall scale kept: the classic estimate changes only the wheels' ratio and the wheelbase";
    return c;
  }
  if (ground_truth_source != "scan") return c;
  const double factor = range_scale ? *range_scale : 0.5 * (c.left + c.right);
  c.separation /= factor;
  c.left /= factor;
  c.right /= factor;
  c.parameters.wheelbase_m = c.separation * recorded.wheelbase_m;
  c.parameters.wheel_diameter_left_m = c.left * recorded.wheel_diameter_left_m;
  c.parameters.wheel_diameter_right_m = c.right * recorded.wheel_diameter_right_m;
  c.scale_source = range_scale ? "range_scale" : "kept";
  c.scale_note = range_scale
                     ? fmt::format("the overall scale from the lidar's distances divided by its stated range scale {} "
                                   "(--scan-range-scale)", *range_scale)
                     : fmt::format("the overall scale kept (the fit's {:.5f} divided out): its ground truth is a lidar's "
                                   "scans, whose range scale cannot be told from the wheels' (give --scan-range-scale S "
                                   "from a range calibration to use the fitted scale)", factor);
  return c;
}

OutputsUse WithRatios(OutputsUse c, const RobotParams& recorded) {
  c.separation = c.parameters.wheelbase_m / recorded.wheelbase_m;
  c.left = c.parameters.wheel_diameter_left_m / recorded.wheel_diameter_left_m;
  c.right = c.parameters.wheel_diameter_right_m / recorded.wheel_diameter_right_m;
  return c;
}

HeldoutComparison SkippedHeldout() {
  HeldoutComparison h;
  h.scheme = kHeldoutSkipped;
  h.notes.push_back("--no-heldout: the held-out comparison of the methods was not run");
  return h;
}

// The parameters the outputs use: `use` classic | refined | recommended (the
// held-out comparison's recommendation; classic when skipped).
OutputsUse ChooseParameters(const CalibrateJobResult& r, const HeldoutComparison& h, const std::string& use) {
  const UmbmarkSummary& s = r.umbmark;
  const std::string classic_name = fmt::format("umbmark_{}", UmbmarkEstimatorToString(s.estimator));
  auto classic = [&](const std::string& why) {
    return OutputsUse{classic_name, s.corrected, why, "ground_truth", "", s.selected.E_b, s.c_L, s.c_R};
  };
  auto refined = [&](const std::string& why) {
    if (!r.refined) throw InvalidOptions("--use refined needs --refine");
    return OutputsUse{"refined", r.refined->refined, why, "ground_truth", "", r.refined->E_b, r.refined->c_L,
                      r.refined->c_R};
  };
  if (use == "classic") return classic("--use classic");
  if (use == "refined") return refined("--use refined");
  if (h.scheme == kHeldoutSkipped) return classic("the held-out comparison was skipped (--no-heldout): the classic result");
  const std::string why = "recommended: " + h.why;
  if (h.recommended == classic_name) return classic(why);
  if (h.recommended == "refined" && r.refined) return refined(why);
  if (const MethodHeldout* m = h.recommended.empty() ? nullptr : h.Find(h.recommended)) {
    return WithRatios({m->method, m->parameters, why, "ground_truth", "", 1.0, 1.0, 1.0}, s.recorded);
  }
  return classic("no method could be compared: the classic result");
}

/// Faults the data show before any fit: swapped encoder channels (quality
/// gate) and unit mix-ups (bad input).
void CheckDataBeforeFit(const CalibrateInput& in) {
  // Swapped encoder channels show in the data themselves: the odometry
  // turns against the ground truth. Said plainly, before any fit.
  if (in.trajectories) {
    const int mirrored = CountMirroredRuns(*in.trajectories, in.recorded);
    if (2 * mirrored > static_cast<int>(in.errors.size())) {
      throw QualityGateError(fmt::format(
          "{}: in {} of {} runs the odometry turns the other way than the ground truth and the cw/ccw label: "
          "the left and right encoder channels (or the sign of the ticks) are swapped; swap the columns "
          "ticks_left/ticks_right (or dist_left_m/dist_right_m) and run again",
          in.label, mirrored, in.errors.size()));
    }
  }
  // Unit mix-ups show in the data too: return errors as large as the
  // square, or runs that travel far more or less than 4 sides.
  if (in.trajectories) {
    if (auto problem = CheckTravelScale(*in.trajectories, in.recorded, in.side_m); !problem.empty())
      throw InputError(in.label, problem);
  }
  if (auto problem = CheckReturnErrorScale(in.errors, in.side_m); !problem.empty()) throw InputError(in.label, problem);
}

/// A unit's fit that passed the plausibility gates (their warnings kept).
struct FittedUnit {
  CalibrateJobResult result;
  PlausibilityReport gate;
};

FittedUnit FitUnit(const CalibrateInput& in, const CalibrateJobOptions& jo) {
  CheckDataBeforeFit(in);
  FittedUnit f;
  f.result = RunCalibrateJob(in, jo);
  // Plausibility gates: never print or write an impossible result.
  f.gate = CheckUmbmarkPlausibility(f.result.umbmark);
  if (f.result.refined) CheckRefinedPlausibility(f.result.umbmark.recorded, f.result.refined->refined, f.gate);
  if (!f.gate.ok()) throw QualityGateError(fmt::format("{}: implausible result: {}", in.label, f.gate.Message()));
  return f;
}

/// The unit's result: the summary's numbers under the JSON's names, the
/// held-out comparison, the parameters the outputs use, the model check
/// and the warnings. `ground_truth_source`: the manifest's [ground_truth]
/// source ("scan": the overall scale of fitted methods is the lidar's).
CalibrateUnitResult Assess(const CalibrateInput& in, FittedUnit f, const CalibrateOptions& o,
                           const CalibrateJobOptions& jo, const std::string& ground_truth_source) {
  CalibrateUnitResult u;
  const CalibrateJobResult& r = f.result;
  const UmbmarkSummary& s = r.umbmark;
  u.heldout = o.no_heldout ? SkippedHeldout() : CompareMethodsHeldout(in, jo, r);
  u.outputs_use = ScaleForScanGroundTruth(ChooseParameters(r, u.heldout, o.use), ground_truth_source,
                                          o.scan_range_scale, s.recorded);
  if (ground_truth_source == "scan") {
    u.heldout.notes.push_back("the ground truth is a lidar's scans (manifest [ground_truth] source = \"scan\"): a "
                              "method fitting the overall wheel scale fits the lidar's range scale; " +
                              u.outputs_use.scale_note);
    if (!u.outputs_use.scale_note.empty()) u.outputs_use.why += "; " + u.outputs_use.scale_note;
  }
  u.model_check = CheckCentresAgainstModel(in, s.runs, r.refined ? r.refined->refined : s.corrected,
                                           jo.refine ? jo.refine->final_turn : true);
  u.warnings = TrustWarnings(r, u.heldout, u.model_check);
  u.design_advice = planning::AdviseCalibration(in, u.outputs_use.parameters);
  u.warnings.insert(u.warnings.end(), u.design_advice.messages.begin(), u.design_advice.messages.end());
  u.warnings.insert(u.warnings.end(), f.gate.warnings.begin(), f.gate.warnings.end());
  if (r.refined && in.trajectories && !HasInteriorGroundTruth(*in.trajectories)) {
    u.warnings.push_back("ground truth only at the first and last sample of each run: the refined fit used the "
                         "return errors (commanded-square model), as for endpoint data, not the path geometry");
  }
  u.input = r.label;
  u.robot_id = RobotIdOf(o, in);
  u.estimator = UmbmarkEstimatorToString(s.estimator);
  u.side_m = s.side_m;
  u.integrator = o.integrator;
  u.E_d = s.selected.E_d;
  u.E_b = s.selected.E_b;
  u.alpha_rad = s.selected.alpha_rad;
  u.beta_rad = s.selected.beta_rad;
  u.R_m = s.selected.R_m;
  u.c_L = s.c_L;
  u.c_R = s.c_R;
  u.E_max_syst_m = s.E_max_syst_m;
  u.sem_m = s.sem_m;
  u.three_sem_m = 3.0 * s.sem_m;
  u.compensation_worthwhile = s.compensation_worthwhile;
  u.parameters = s.corrected;
  u.recorded_parameters = s.recorded;
  for (std::size_t i = 0; i < s.runs.size(); ++i) {
    const RunFlag& g = s.runs[i];
    u.runs.push_back({g.run, g.direction, g.ex_m, g.ey_m, in.errors[i].etheta_rad, g.score, g.outlier, g.excluded,
                      g.rejected});
  }
  u.experiments = in.files;
  if (r.refine_failure) u.refine_error = r.refine_failure->what();
  u.job = std::move(f.result);
  return u;
}

// One command, in steps: Load each input into calibration units, Fit and
// gate each unit, Conclude it (assess, write its files). With one input,
// errors propagate; with several (a batch), a failing input or unit is
// recorded and skipped, and the exit status is the worst at the end. The
// members are the state the steps share.
class CalibrateRun {
 public:
  CalibrateRun(CalibrateOptions& o, const std::function<void(const CalibrateOutcome&)>& on_unit);
  CalibrateResult Run();

 private:
  std::optional<std::vector<CalibrateInput>> Load(std::size_t k);
  std::optional<FittedUnit> Fit(const CalibrateInput& in);
  void Conclude(const std::string& path, bool manifest, const CalibrateInput& in, bool several, FittedUnit f);
  std::string UniqueTag(const std::string& path, const CalibrateInput& in);
  void WriteOutputs(const CalibrateInput& in, const CalibrateUnitResult& u, const std::string& tag, bool several);
  void Record(CalibrateOutcome outcome);
  void RecordFailure(const std::string& label, CalibrateOutcome::Failure kind, const std::string& error, int status,
                     std::string solver = "");

  CalibrateOptions& o_;
  const std::function<void(const CalibrateOutcome&)>& on_unit_;
  CalibrateJobOptions jo_;
  std::size_t count_;  ///< inputs: files, then in-memory data
  bool batch_;
  std::optional<io::OutputSet> own_outputs_;
  io::OutputSet* outs_;
  std::set<std::string> tags_used_;
  CalibrateResult result_;
  double done_ = 0.0;
};

CalibrateRun::CalibrateRun(CalibrateOptions& o, const std::function<void(const CalibrateOutcome&)>& on_unit)
    : o_(o), on_unit_(on_unit), jo_(JobOptions(o)), count_(o.inputs.size() + o.data.size()), batch_(count_ > 1) {
  // Within an input, the held-out comparison (the long part) moves the
  // progress by its folds.
  if (o_.progress) {
    jo_.progress = [this](double folds_done, double folds) {
      o_.progress(done_ - 1.0 + (folds > 0.0 ? folds_done / folds : 1.0), static_cast<double>(count_));
    };
  }
  outs_ = o.outputs;
  if (!outs_) outs_ = &own_outputs_.emplace();
  // Output safety: no output may be an input or another output.
  for (const auto& path : o.inputs) {
    outs_->AddInput(path);
    if (!io::IsManifestPath(path)) continue;
    try {
      outs_->AddManifestInputs(path, io::ReadManifest(path));
    } catch (const InputError&) {
      // reported when the manifest is read
    }
  }
  outs_->AddInput(o.robot.robot_file);
  outs_->AddOutput("--ros2", o.ros2);
  outs_->AddOutput("--plot", o.plot);
  outs_->AddOutput("--report", o.report);
  outs_->Check();
}

CalibrateResult CalibrateRun::Run() {
  result_.batch = batch_;
  for (std::size_t k = 0; k < count_; ++k) {
    if (o_.progress) o_.progress(done_, static_cast<double>(count_));
    done_ += 1.0;
    const std::string path = k < o_.inputs.size() ? o_.inputs[k] : o_.data[k - o_.inputs.size()].name;
    const std::optional<std::vector<CalibrateInput>> inputs = Load(k);
    if (!inputs) continue;
    const bool several = batch_ || inputs->size() > 1;
    result_.batch = result_.batch || inputs->size() > 1;
    for (const auto& in : *inputs) {
      const bool manifest = k < o_.inputs.size() && io::IsManifestPath(path);
      if (std::optional<FittedUnit> fitted = Fit(in)) Conclude(path, manifest, in, several, std::move(*fitted));
    }
  }
  if (o_.progress) o_.progress(static_cast<double>(count_), static_cast<double>(count_));
  return std::move(result_);
}

void CalibrateRun::Record(CalibrateOutcome outcome) {
  result_.exit_status = std::max(result_.exit_status, outcome.exit_status);
  result_.failed = result_.exit_status != 0;
  if (on_unit_) on_unit_(outcome);
  result_.results.push_back(std::move(outcome));
}

void CalibrateRun::RecordFailure(const std::string& label, CalibrateOutcome::Failure kind, const std::string& error,
                                 int status, std::string solver) {
  CalibrateOutcome out;
  out.input = label;
  out.failure = kind;
  out.error = error;
  out.solver = std::move(solver);
  out.exit_status = status;
  Record(std::move(out));
}

/// The input's calibration units; nullopt when a batch input cannot be read
/// (recorded).
std::optional<std::vector<CalibrateInput>> CalibrateRun::Load(std::size_t k) {
  const std::string& path = k < o_.inputs.size() ? o_.inputs[k] : o_.data[k - o_.inputs.size()].name;
  try {
    if (k < o_.inputs.size()) return LoadFile(path, o_, jo_.integrator);
    if (!o_.side_m) throw InvalidOptions("--side S (square side in metres) is required for CSV input");
    CalibrateData& d = o_.data[k - o_.inputs.size()];
    return std::vector<CalibrateInput>{
        FromRunFile(std::move(d.runs), o_.robot.Resolve(), *o_.side_m, jo_.integrator, d.name)};
  } catch (const InputError& e) {
    if (!batch_) throw;
    RecordFailure(path, CalibrateOutcome::Failure::kInput, e.what(), 1);
    return std::nullopt;
  }
}

/// Checks the data, calibrates the unit and applies the plausibility gates;
/// nullopt when a batch unit fails (recorded).
std::optional<FittedUnit> CalibrateRun::Fit(const CalibrateInput& in) {
  try {
    return FitUnit(in, jo_);
  } catch (const RefineError& e) {
    // What is known (solver report, identifiability) goes with the failure:
    // the quality gate fails, never numbers from a failed fit.
    RecordFailure(in.label, CalibrateOutcome::Failure::kRefine, e.what(), 3, RefineReport(e.summary()));
    if (!batch_) throw;
  } catch (const QualityGateError& e) {
    if (!batch_) throw;
    RecordFailure(in.label, CalibrateOutcome::Failure::kQualityGate, e.what(), 3);
  } catch (const InputError& e) {
    if (!batch_) throw;
    RecordFailure(in.label, CalibrateOutcome::Failure::kInput, e.what(), 1);
  }
  return std::nullopt;
}

/// A fitted unit: assessed, its files written, recorded.
void CalibrateRun::Conclude(const std::string& path, bool manifest, const CalibrateInput& in, bool several,
                            FittedUnit f) {
  CalibrateOutcome out;
  out.input = in.label;
  out.result = Assess(in, std::move(f), o_, jo_, manifest ? io::ReadGroundTruthSource(path) : std::string());
  const CalibrateUnitResult& u = *out.result;
  WriteOutputs(in, u, UniqueTag(path, in), several);
  // The classic result stands; the refined fit failed its quality gate.
  if (u.refine_error) out.exit_status = 3;
  for (const auto& w : u.warnings) result_.warnings.push_back(batch_ ? in.label + ": " + w : w);
  Record(std::move(out));
}

/// The unit's dataset tag (DatasetTag), numbered from 2 when already used.
std::string CalibrateRun::UniqueTag(const std::string& path, const CalibrateInput& in) {
  std::string tag = DatasetTag(path, in);
  for (int k = 2; !tags_used_.insert(tag).second; ++k) tag = fmt::format("{}-{}", DatasetTag(path, in), k);
  return tag;
}

/// ros2, plot and report of one unit (tagged with the dataset when the
/// command has several units).
void CalibrateRun::WriteOutputs(const CalibrateInput& in, const CalibrateUnitResult& u, const std::string& tag,
                                bool several) {
  auto file_of = [&](const std::string& path) {
    return several ? (std::filesystem::path(path).parent_path() /
                      (std::filesystem::path(path).stem().string() + "-" + tag +
                       std::filesystem::path(path).extension().string()))
                         .string()
                   : path;
  };
  if (!o_.ros2.empty()) {
    const std::string file = file_of(o_.ros2);
    outs_->Write(file, Ros2Parameters(u, o_.controller));
    result_.written.push_back(file + " (ros2_control parameters)");
  }
  // The plot and the report show the calibration `use` selects (by default
  // the recommended one), and say which.
  const std::string& which = u.outputs_use.method;
  std::string svg;
  if (!o_.plot.empty() || !o_.report.empty())
    svg = CalibrationPlotSvg(in, u.job, jo_.integrator, u.outputs_use.parameters, which);
  if (!o_.plot.empty()) {
    const std::string file = file_of(o_.plot);
    outs_->Write(file, svg);
    result_.written.push_back(file + " (plot: " + which + ")");
  }
  if (!o_.report.empty()) {
    const std::string file = file_of(o_.report);
    outs_->Write(file, CalibrationReportHtml(u, svg));
    result_.written.push_back(file + " (HTML report)");
  }
}

}  // namespace

std::string CalibrateOutcome::Message() const {
  switch (failure) {
    case Failure::kInput:
      return error;
    case Failure::kQualityGate:
      return "umbmark: quality gate failed: " + error;
    case Failure::kRefine:
      return fmt::format("{}: refined calibration failed: {}\n{}", input, error, solver);
    case Failure::kNone:
      break;
  }
  if (result && result->refine_error) {
    return fmt::format("umbmark: quality gate failed: {}: refined calibration failed: {}\n  solver: {}", input,
                       *result->refine_error, result->job.refine_failure->summary().solver.brief_report);
  }
  return {};
}

CalibrateResult Calibrate(CalibrateOptions options, const std::function<void(const CalibrateOutcome&)>& on_unit) {
  if (std::string err = options.Check(); !err.empty()) throw InvalidOptions(err);
  CalibrateRun run(options, on_unit);
  return run.Run();
}

}  // namespace umbmark::api
