// `umbmark calibrate DATA... --robot R.toml --side S [--estimator x|y|mean]`:
// classic UMBmark (Borenstein & Feng) from CW/CCW square runs, endpoint or
// trajectory CSV, or campaign manifests (their square experiments). Several
// inputs give one result each plus a summary table (factory batch use).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "calibrate_plot.hpp"
#include "calibration/calibrate_job.hpp"
#include "calibration/heldout.hpp"
#include "calibration/plausibility.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "progress.hpp"
#include "core/angles.hpp"
#include "core/errors.hpp"
#include "output/atomic_write.hpp"
#include "report/html_report.hpp"
#include "formats/data_file.hpp"
#include "formats/manifest.hpp"
#include "formats/robot_id.hpp"
#include "formats/ros2_params.hpp"
#include "planning/advice.hpp"

namespace umbmark::cli {

namespace {

struct CalibrateOptions {
  std::vector<std::string> inputs;
  RobotFlags robot;
  std::optional<double> side_m;
  std::string estimator = "mean";
  std::string integrator = "arc";
  std::string ed_wheelbase = "corrected";
  std::vector<std::string> exclude_runs;
  bool reject_outliers = false;
  double outlier_threshold = 3.5;
  JsonFlag json;
  std::string ros2;
  std::string controller = "diff_drive_controller";
  std::string plot;
  std::string report;
  bool refine = false;
  std::vector<std::string> fix, free;
  std::string loss = "huber";
  double loss_scale_m = 0.02;
  int samples_per_run = 100;
  std::string sampling = "per_run";
  std::string start_pose = "session_frame";
  double heading_weight = 2.0;
  std::string use = "recommended";
  bool per_experiment = false;
  bool no_heldout = false;  // --no-heldout: skip the held-out comparison
  std::optional<double> scan_range_scale;  // --scan-range-scale: a lidar's range calibration (scan ground truth)
};

// The parameters --ros2 and --plot use: --use classic | refined |
// recommended (the held-out comparison's recommendation; classic when skipped).
struct Chosen {
  std::string method;  ///< umbmark_<estimator> | refined | plain_least_squares | recorded
  RobotParams parameters;
  std::string why;
  /// ros2 multipliers (wheel separation, left, right radius) relative to the
  /// recorded robot: the method's own factors where it has them (exact), else
  /// ratios of the parameters.
  double separation = 1.0, left = 1.0, right = 1.0;
  /// Where the multipliers' overall scale comes from, for the YAML comment
  /// and the JSON (`outputs_use.scale_source`): "kept" (the mean wheel
  /// diameter of the recorded robot, as classic UMBmark), "ground_truth"
  /// (fitted to the ground truth's distances), "range_scale" (fitted to a
  /// lidar's distances corrected by --scan-range-scale).
  std::string scale_source = "ground_truth";
  std::string scale_note = "";
};

// Scan ground truth (a lidar's registration) carries the lidar's range
// scale: from scans alone only the wheels' ratio and the wheelbase relative
// to them are observable, not their overall scale. The classic estimate
// keeps the recorded scale; a method fitted to the scans' distances is
// rescaled by a stated range calibration (--scan-range-scale), else to keep
// the recorded scale too (mean radius multiplier 1).
Chosen ScaleForScanGroundTruth(Chosen c, const std::string& ground_truth_source, std::optional<double> range_scale,
                               const RobotParams& recorded) {
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

Chosen WithRatios(Chosen c, const RobotParams& recorded) {
  c.separation = c.parameters.wheelbase_m / recorded.wheelbase_m;
  c.left = c.parameters.wheel_diameter_left_m / recorded.wheel_diameter_left_m;
  c.right = c.parameters.wheel_diameter_right_m / recorded.wheel_diameter_right_m;
  return c;
}

/// HeldoutComparison::scheme when --no-heldout skipped the comparison.
constexpr const char* kHeldoutSkipped = "skipped";

HeldoutComparison SkippedHeldout() {
  HeldoutComparison h;
  h.scheme = kHeldoutSkipped;
  h.notes.push_back("--no-heldout: the held-out comparison of the methods was not run");
  return h;
}

Chosen ChooseParameters(const CalibrateJobResult& r, const HeldoutComparison& h, const std::string& use) {
  const UmbmarkSummary& s = r.umbmark;
  const std::string classic_name = fmt::format("umbmark_{}", UmbmarkEstimatorToString(s.estimator));
  auto classic = [&](const std::string& why) {
    return Chosen{classic_name, s.corrected, why, s.selected.E_b, s.c_L, s.c_R};
  };
  auto refined = [&](const std::string& why) {
    if (!r.refined) throw InvalidOptions("--use refined needs --refine");
    return Chosen{"refined", r.refined->refined, why, r.refined->E_b, r.refined->c_L, r.refined->c_R};
  };
  if (use == "classic") return classic("--use classic");
  if (use == "refined") return refined("--use refined");
  if (h.scheme == kHeldoutSkipped)
    return classic("the held-out comparison was skipped (--no-heldout): the classic result");
  const std::string why = "recommended: " + h.why;
  if (h.recommended == classic_name) return classic(why);
  if (h.recommended == "refined" && r.refined) return refined(why);
  if (const MethodHeldout* m = h.recommended.empty() ? nullptr : h.Find(h.recommended)) {
    return WithRatios({m->method, m->parameters, why}, s.recorded);
  }
  return classic("no method could be compared: the classic result");
}

// Turns one command-line input into calibration inputs. A manifest's square
// experiments pool into one calibration (one side length), or give one each
// with --per-experiment.
std::vector<CalibrateInput> LoadInputs(const std::string& path, const CalibrateOptions& o, Integrator integrator) {
  std::vector<CalibrateInput> out;
  auto from_file = [&](const std::string& file, const RobotParams& robot, double side, const std::string& label) {
    io::RunFile rf = io::ReadRunFile(file);
    if (auto* t = std::get_if<TrajectoryData>(&rf)) {
      return InputFromTrajectories(std::move(*t), robot, side, integrator, label);
    }
    return InputFromEndpoints(std::get<EndpointData>(rf), robot, side, label);
  };
  if (io::IsManifestPath(path)) {
    const Manifest m = io::ReadManifest(path);
    const RobotParams robot = o.robot.Resolve(m.robot);
    std::vector<std::string> tags;
    std::vector<TrajectoryData> unseen;  // other shapes: held out for the comparison of methods
    int index = 0;
    for (const auto& e : m.experiments) {
      ++index;
      if (e.kind != ExperimentKind::kSquare) {
        io::RunFile rf = io::ReadRunFile(e.resolved_file);
        if (auto* t = std::get_if<TrajectoryData>(&rf)) {
          // Only runs with ground truth at the start and later (a final error).
          std::erase_if(t->runs, [](const TrajectoryRun& r) {
            if (r.size() < 2 || !r.HasGroundTruth(0)) return true;
            for (std::size_t i = 1; i < r.size(); ++i)
              if (r.HasGroundTruth(i)) return false;
            return true;
          });
          if (!t->runs.empty()) unseen.push_back(std::move(*t));
        }
        continue;
      }
      const double side = o.side_m.value_or(e.side_m);
      out.push_back(from_file(e.resolved_file, robot, side, fmt::format("{}#{}", path, index)));
      tags.push_back(std::to_string(index));
    }
    if (out.empty()) throw InputError(path, "the manifest has no square experiment to calibrate from");
    for (auto& in : out) in.unseen = unseen;
    if (!o.per_experiment && out.size() > 1) {
      return {PoolInputs(out, tags, fmt::format("{} (experiments {} pooled)", path, fmt::join(tags, ", ")))};
    }
  } else {
    if (!o.side_m) throw InvalidOptions("--side S (square side in metres) is required for CSV input");
    out.push_back(from_file(path, o.robot.Resolve(), *o.side_m, path));
  }
  return out;
}

// The name a batch output is tagged with: the dataset, i.e. the input file's
// stem, or its folder when the file has a generic name (an import's
// campaign.toml / runs.csv), plus the experiment for --per-experiment.
std::string DatasetTag(const std::string& input_path, const CalibrateInput& in) {
  const std::filesystem::path p(input_path);
  std::string stem = p.stem().string();
  if ((stem == "campaign" || stem == "runs") && p.has_parent_path() && !p.parent_path().filename().empty())
    stem = p.parent_path().filename().string();
  if (const auto hash = in.label.rfind('#'); hash != std::string::npos && in.label.find(' ', hash) == std::string::npos)
    stem += "-exp" + in.label.substr(hash + 1);
  return stem;
}

nlohmann::json JsonCluster(const ClusterStats& c) {
  return {{"n", c.n}, {"x_m", c.x_cg_m}, {"y_m", c.y_cg_m}, {"r_m", c.r_cg_m}, {"sigma_m", c.sigma_m}, {"sem_m", c.sem_m}};
}

nlohmann::json JsonEstimate(const UmbmarkEstimate& e) {
  return {{"alpha_rad", e.alpha_rad}, {"beta_rad", e.beta_rad}, {"R_m", JsonNumber(e.R_m)}, {"E_b", e.E_b}, {"E_d", e.E_d}};
}

nlohmann::json JsonHeldout(const HeldoutComparison& h) {
  nlohmann::json methods = nlohmann::json::object();
  for (const auto& m : h.methods) {
    methods[m.method] = {{"mean_m", JsonNumber(m.mean_m)}, {"sem_m", JsonNumber(m.sem_m)},
                         {"rms_m", JsonNumber(m.rms_m)},   {"folds", m.folds},
                         {"failed_folds", m.failed_folds}, {"parameters", JsonParams(m.parameters)}};
  }
  return methods;
}

/// Each run's return error, outlier score and flags (JSON `runs`).
nlohmann::json JsonRuns(const CalibrateInput& in, const UmbmarkSummary& s) {
  nlohmann::json runs = nlohmann::json::array();
  for (std::size_t i = 0; i < s.runs.size(); ++i) {
    const auto& f = s.runs[i];
    nlohmann::json jr = {{"run", f.run},         {"direction", f.direction}, {"ex_m", f.ex_m},
                         {"ey_m", f.ey_m},       {"outlier", f.outlier},     {"excluded", f.excluded},
                         {"rejected", f.rejected}};
    jr["etheta_rad"] = in.errors[i].etheta_rad ? nlohmann::json(*in.errors[i].etheta_rad) : nlohmann::json(nullptr);
    jr["outlier_score"] = f.score ? nlohmann::json(*f.score) : nlohmann::json(nullptr);
    runs.push_back(jr);
  }
  return runs;
}

/// JSON `heldout`: the scheme, the recommendation's expected error and the
/// runner-up (nulls where --no-heldout skipped the comparison or there is
/// none).
nlohmann::json JsonHeldoutSummary(const HeldoutComparison& h) {
  const bool skipped = h.scheme == kHeldoutSkipped;
  return {{"scheme", h.scheme},
          {"measure", h.measure},
          {"left_out", h.left_out},
          {"sessions", h.sessions},
          {"baseline", h.baseline.empty() ? nlohmann::json(nullptr) : nlohmann::json(h.baseline)},
          {"why", h.why},
          {"expected_error_m", skipped ? nlohmann::json(nullptr) : JsonNumber(h.expected_error_m)},
          {"expected_error_sem_m", skipped ? nlohmann::json(nullptr) : JsonNumber(h.expected_error_sem_m)},
          {"runner_up", h.runner_up.empty() ? nlohmann::json(nullptr) : nlohmann::json(h.runner_up)},
          {"runner_up_difference_m", h.runner_up.empty() ? nlohmann::json(nullptr) : JsonNumber(h.runner_up_difference_m)},
          {"runner_up_difference_sem_m",
           h.runner_up.empty() ? nlohmann::json(nullptr) : JsonNumber(h.runner_up_difference_sem_m)},
          {"checked", h.checked},
          {"not_checked", h.not_checked},
          {"notes", h.notes}};
}

// The robot's id (formats/robot_id.hpp): from --robot's file, else from the
// manifest the input came from ("M.toml#k"), else none.
std::string RobotIdOf(const CalibrateOptions& o, const CalibrateInput& in) {
  if (!o.robot.robot_file.empty()) return io::ReadRobotId(o.robot.robot_file);
  std::string path = in.label;
  if (const auto hash = path.rfind('#'); hash != std::string::npos &&
      path.find_first_not_of("0123456789", hash + 1) == std::string::npos && hash + 1 < path.size())
    path.resize(hash);
  return io::IsManifestPath(path) ? io::ReadRobotId(path) : std::string();
}

nlohmann::json JsonResult(const CalibrateInput& in, const CalibrateJobResult& r, const CalibrateOptions& o,
                          const HeldoutComparison& h, const ModelCheck& check, const Chosen& chosen,
                          const std::vector<std::string>& warnings) {
  const UmbmarkSummary& s = r.umbmark;
  nlohmann::json j;
  j["input"] = r.label;
  if (const std::string id = RobotIdOf(o, in); !id.empty()) j["robot_id"] = id;  // for summarize
  j["method"] = "umbmark";
  j["estimator"] = UmbmarkEstimatorToString(s.estimator);
  j["side_m"] = s.side_m;
  j["integrator"] = o.integrator;
  j["E_d"] = s.selected.E_d;
  j["E_b"] = s.selected.E_b;
  j["alpha_rad"] = s.selected.alpha_rad;
  j["beta_rad"] = s.selected.beta_rad;
  j["R_m"] = JsonNumber(s.selected.R_m);
  j["c_L"] = s.c_L;
  j["c_R"] = s.c_R;
  j["E_max_syst_m"] = s.E_max_syst_m;
  j["parameters"] = JsonParams(s.corrected);
  j["recorded_parameters"] = JsonParams(s.recorded);
  j["estimates"] = {{"x", JsonEstimate(s.from_x)},
                    {"y", JsonEstimate(s.from_y)},
                    {"spread", {{"E_d", s.spread_E_d}, {"E_b", s.spread_E_b}}}};
  j["centres_of_gravity"] = {{"cw", JsonCluster(s.cw)}, {"ccw", JsonCluster(s.ccw)}};
  j["sem_m"] = s.sem_m;
  j["three_sem_m"] = 3.0 * s.sem_m;
  j["compensation_worthwhile"] = s.compensation_worthwhile;
  j["runs"] = JsonRuns(in, s);
  j["experiments"] = in.files;
  if (r.refine_failure) j["refine_error"] = r.refine_failure->what();
  if (r.refined) {
    j["refined"] = RefinedToJson(*r.refined);
    if (r.refined_evaluation) {
      j["refined"]["evaluation"] = {{"summary", JsonEvaluationSummary(*r.refined_evaluation)},
                                    {"runs", JsonEvaluationRuns(*r.refined_evaluation)}};
    }
  }
  // --no-heldout: both keys say so instead of naming a method.
  const bool skipped = h.scheme == kHeldoutSkipped;
  j["heldout_error"] = skipped ? nlohmann::json(kHeldoutSkipped) : JsonHeldout(h);
  j["heldout"] = JsonHeldoutSummary(h);
  j["recommended"] = skipped              ? nlohmann::json(kHeldoutSkipped)
                     : h.recommended.empty() ? nlohmann::json(nullptr)
                                             : nlohmann::json(h.recommended);
  if (r.refined && h.Find("refined")) j["refined"]["heldout_error"] = JsonHeldout(h)["refined"];
  j["model_check"] = check.available ? nlohmann::json{{"reduced_chi2", check.reduced_chi2},
                                                      {"dof", check.dof},
                                                      {"p_value", check.p_value}}
                                     : nlohmann::json(nullptr);
  j["outputs_use"] = {{"method", chosen.method},
                      {"parameters", JsonParams(chosen.parameters)},
                      {"why", chosen.why},
                      {"scale_source", chosen.scale_source}};
  j["warnings"] = warnings;
  if (r.evaluation) {
    const auto& a = *r.evaluation;
    j["evaluation"] = {{"before", JsonEvaluationSummary(a.before)},
                       {"after", JsonEvaluationSummary(a.after)},
                       {"before_runs", JsonEvaluationRuns(a.before)},
                       {"after_runs", JsonEvaluationRuns(a.after)},
                       {"E_max_syst_after_m", a.E_max_syst_m},
                       {"centres_of_gravity_after", {{"cw", JsonCluster(a.cw)}, {"ccw", JsonCluster(a.ccw)}}},
                       {"sem_after_m", a.sem_m},
                       {"second_pass_worthwhile", a.second_pass_worthwhile}};
  }
  return j;
}

void PrintEvaluation(const char* title, const EvaluationSummary& e) {
  fmt::print("  {:<7} position error max {:7.2f} mm (mean over runs {:6.2f}), final max {:7.2f} mm (mean {:6.2f});"
             " heading max {:6.3f} deg, final max {:6.3f} deg\n",
             title, e.max_max_position_error_m * 1e3, e.mean_max_position_error_m * 1e3,
             e.max_final_position_error_m * 1e3, e.mean_final_position_error_m * 1e3,
             Rad2Deg(e.max_max_heading_error_rad), Rad2Deg(e.max_final_heading_error_rad));
}

/// What the held-out scheme left out, for the table's title.
std::string SchemeText(const HeldoutComparison& h) {
  if (h.scheme == "unseen_paths") return "paths of other shapes that no calibration saw";
  if (h.scheme == "leave_one_session_out") return fmt::format("left-out sessions (of {})", h.sessions);
  if (h.scheme == "k_fold_over_runs") return "left-out runs (10-fold over runs)";
  return "left-out runs (leave-one-run-out)";
}

/// The held-out table: each method's prediction error and the recommendation.
void PrintHeldoutTable(const HeldoutComparison& h) {
  const std::string measure = h.measure == "final_position_error_m" ? "final position error, odometry from the first "
                                                                      "ground-truth pose"
                              : h.measure == "max_position_error_m" ? "largest position error along the left-out run"
                                                                    : "left-out return error vs the model's prediction";
  fmt::print("Which calibration to trust: prediction error on {} ({} folds, {})\n", SchemeText(h),
             h.methods.empty() ? 0 : h.methods.front().folds, measure);
  const MethodHeldout* lowest = nullptr;
  for (const auto& m : h.methods) {
    if ((m.Recommendable() || m.method == "recorded") && m.folds > 0 && (!lowest || m.mean_m < lowest->mean_m))
      lowest = &m;
  }
  for (const auto& m : h.methods) {
    std::string mark;
    if (&m == lowest) mark += "   lowest";
    if (m.method == h.recommended) mark += "   <- recommended";
    fmt::print("  {:<20} {:7.2f} mm +- {:5.2f} (SE){}{}\n", m.method, m.mean_m * 1e3, m.sem_m * 1e3,
               m.failed_folds ? fmt::format(", failed on {} folds", m.failed_folds) : "", mark);
  }
  for (const auto& n : h.notes) fmt::print("  note: {}\n", n);
  for (const auto& c : h.checked) fmt::print("  the held-out runs checked: {}\n", c);
  for (const auto& c : h.not_checked) fmt::print("  they could not check: {}\n", c);
  if (!h.recommended.empty()) {
    const MethodHeldout* m = h.Find(h.recommended);
    fmt::print("  Put {} on the robot: wheelbase {:.6f} m, left diameter {:.6f} m, right diameter {:.6f} m\n",
               h.recommended, m->parameters.wheelbase_m, m->parameters.wheel_diameter_left_m,
               m->parameters.wheel_diameter_right_m);
    fmt::print("  ({})\n", h.why);
    fmt::print("  Expected error on paths it has not seen: {:.2f} mm +- {:.2f} (SE){}\n", h.expected_error_m * 1e3,
               h.expected_error_sem_m * 1e3,
               h.scheme == "unseen_paths" || h.scheme == "leave_one_session_out"
                   ? ""
                   : " (from left-out square runs of the same session: other shapes and days may differ)");
    if (!h.runner_up.empty()) {
      fmt::print("  runner-up {}: {:+.2f} mm +- {:.2f} (SE) against it\n", h.runner_up, h.runner_up_difference_m * 1e3,
                 h.runner_up_difference_sem_m * 1e3);
    }
  }
}

void PrintHeldout(const HeldoutComparison& h, const Chosen& chosen, const std::vector<std::string>& warnings,
                  const CalibrateOptions& o) {
  if (h.scheme == kHeldoutSkipped) {
    fmt::print("Which calibration to trust: not compared (--no-heldout); run without it for the held-out "
               "prediction error of each method\n");
  } else {
    PrintHeldoutTable(h);
  }
  if (!o.ros2.empty() || !o.plot.empty()) {
    fmt::print("  --ros2/--plot use {} ({})\n", chosen.method, chosen.why);
  }
  for (const auto& w : warnings) fmt::print("  WARNING: {}\n", w);
}

void PrintResult(const CalibrateJobResult& r) {
  const UmbmarkSummary& s = r.umbmark;
  fmt::print("UMBmark calibration: {}\n", r.label);
  fmt::print("  square side {} m, estimator {}, {} runs ({} cw, {} ccw used)\n", s.side_m,
             UmbmarkEstimatorToString(s.estimator), s.runs.size(), s.cw.n, s.ccw.n);
  fmt::print("  centre of gravity cw  ({:+8.2f}, {:+8.2f}) mm  r = {:7.2f} mm  sigma {:6.2f} mm  SEM {:6.2f} mm\n",
             s.cw.x_cg_m * 1e3, s.cw.y_cg_m * 1e3, s.cw.r_cg_m * 1e3, s.cw.sigma_m * 1e3, s.cw.sem_m * 1e3);
  fmt::print("  centre of gravity ccw ({:+8.2f}, {:+8.2f}) mm  r = {:7.2f} mm  sigma {:6.2f} mm  SEM {:6.2f} mm\n",
             s.ccw.x_cg_m * 1e3, s.ccw.y_cg_m * 1e3, s.ccw.r_cg_m * 1e3, s.ccw.sigma_m * 1e3, s.ccw.sem_m * 1e3);
  const bool scatter_known = s.cw.n >= 2 && s.ccw.n >= 2 && s.sem_m > 0.0;
  fmt::print("  E_max,syst = {:.2f} mm   (3*SEM = {:.2f} mm: {})\n", s.E_max_syst_m * 1e3, 3e3 * s.sem_m,
             !scatter_known             ? "scatter unknown, so the 3*SEM test cannot decide (see the warnings)"
             : s.compensation_worthwhile ? "systematic error stands out of the scatter, compensation worthwhile"
                                         : "systematic error within the scatter, compensation unlikely to help");
  fmt::print("  alpha = {:+.5f} deg, beta = {:+.5f} deg, R = {:.3f} m\n", Rad2Deg(s.selected.alpha_rad),
             Rad2Deg(s.selected.beta_rad), s.selected.R_m);
  fmt::print("  E_d = {:.6f}   E_b = {:.6f}   c_L = {:.6f}   c_R = {:.6f}\n", s.selected.E_d, s.selected.E_b, s.c_L, s.c_R);
  fmt::print("  x vs y estimators: E_d {:.6f} / {:.6f}, E_b {:.6f} / {:.6f} (spread {:.2e}, {:.2e})\n", s.from_x.E_d,
             s.from_y.E_d, s.from_x.E_b, s.from_y.E_b, s.spread_E_d, s.spread_E_b);
  fmt::print("  wheelbase        {:.6f} m -> {:.6f} m\n", s.recorded.wheelbase_m, s.corrected.wheelbase_m);
  fmt::print("  left diameter    {:.6f} m -> {:.6f} m\n", s.recorded.wheel_diameter_left_m, s.corrected.wheel_diameter_left_m);
  fmt::print("  right diameter   {:.6f} m -> {:.6f} m\n", s.recorded.wheel_diameter_right_m, s.corrected.wheel_diameter_right_m);
  for (const auto& f : s.runs) {
    if (!f.outlier && !f.excluded) continue;
    fmt::print("  run {} ({}): {}{}\n", f.run, f.direction,
               f.excluded ? "excluded by --exclude-runs" : fmt::format("outlier, robust score {:.1f}", *f.score),
               f.rejected ? ", rejected (--reject-outliers)" : (f.outlier ? ", kept (use --reject-outliers to drop)" : ""));
  }
  if (r.evaluation) {
    const auto& a = *r.evaluation;
    PrintEvaluation("before", a.before);
    PrintEvaluation("after", a.after);
    fmt::print("  after correction: E_max,syst = {:.2f} mm, 3*SEM = {:.2f} mm: {}\n", a.E_max_syst_m * 1e3, 3e3 * a.sem_m,
               a.second_pass_worthwhile ? "a second compensation pass is indicated"
                                        : "a second compensation pass is unlikely to help");
  }
  if (r.refined) {
    fmt::print("Refined calibration (Ceres, {}):\n", RefineInputKindToString(r.refined->input));
    fmt::print("{}", RefineReport(*r.refined));
    if (r.refined_evaluation) PrintEvaluation("refined", *r.refined_evaluation);
  }
}

// diff_drive_controller multipliers of the chosen calibration (--use): each
// parameter relative to the one the runs were recorded with.
std::string Ros2Parameters(const CalibrateJobResult& r, const Chosen& chosen, const std::string& controller) {
  io::DiffDriveMultipliers m;
  m.wheel_separation_multiplier = chosen.separation;
  m.left_wheel_radius_multiplier = chosen.left;
  m.right_wheel_radius_multiplier = chosen.right;
  return io::FormatDiffDriveCalibration(
      controller, m, r.umbmark.recorded,
      {fmt::format("ros2_control diff_drive_controller parameters from umbmark calibrate: {} ({})", chosen.method,
                   r.label),
       chosen.scale_note.empty() ? std::string("overall scale: fitted to the ground truth's distances")
                                 : "overall scale: " + chosen.scale_note,
       "Load with: ros2 param load /" + controller + " FILE (or add to the controller's --param-file list)"});
}

/// The report's held-out section, from the result JSON: each method's
/// error on the held-out runs or paths, the recommendation and its expected
/// error on paths it has not seen.
void HeldoutSection(io::HtmlReport& rep, const nlohmann::json& j) {
  if (!j.contains("heldout_error") || !j["heldout_error"].is_object()) return;
  const nlohmann::json& h = j["heldout"];
  rep.Heading("Which calibration to trust: error on runs it did not see");
  std::vector<std::vector<std::string>> rows;
  const std::string recommended = j["recommended"].is_string() ? j["recommended"].get<std::string>() : "";
  for (const auto& [method, m] : j["heldout_error"].items()) {
    auto mm = [](const nlohmann::json& v) { return v.is_number() ? fmt::format("{:.2f}", v.get<double>() * 1e3) : "-"; };
    rows.push_back({method, mm(m["mean_m"]), mm(m["sem_m"]), std::to_string(m["folds"].get<int>()),
                    method == recommended ? "recommended" : ""});
  }
  rep.Table({"method", "mean [mm]", "SE [mm]", "folds", ""}, rows);
  const auto num = [](const nlohmann::json& v) { return v.is_number() ? v.get<double>() * 1e3 : 0.0; };
  rep.Paragraph(fmt::format("Held out: {} ({}). Recommended: {} ({}). Expected error on paths it has not seen: "
                            "{:.2f} mm +- {:.2f} (SE).",
                            h["scheme"].get<std::string>(), h["measure"].get<std::string>(), recommended,
                            h["why"].get<std::string>(), num(h["expected_error_m"]), num(h["expected_error_sem_m"])));
}

// The report's headline: is a correction worthwhile, and by how much the
// classic correction shrinks E_max,syst on the same runs.
void ReportHeadline(io::HtmlReport& rep, const CalibrateJobResult& r, const std::string& which) {
  const UmbmarkSummary& s = r.umbmark;
  const double emax = s.E_max_syst_m * 1e3, three_sem = 3e3 * s.sem_m;
  if (!s.compensation_worthwhile) {
    rep.Headline(fmt::format("The systematic error E_max,syst = {:.2f} mm lies within the run-to-run scatter (3 SEM = {:.2f} "
                             "mm): a correction is unlikely to help.",
                             emax, three_sem),
                 io::HtmlReport::Level::kInfo);
  } else if (r.evaluation) {
    // r.evaluation is the classic UMBmark correction's (RunCalibrateJob); the
    // recommended set can be another method, whose return errors the plot shows.
    const double after = r.evaluation->E_max_syst_m * 1e3;
    const std::string shown_note =
        which.rfind("umbmark", 0) == 0
            ? std::string()
            : fmt::format(" The recommended calibration is {}: its return errors are in the plot.", which);
    rep.Headline(fmt::format("Correction worthwhile: E_max,syst {:.2f} mm before, {:.2f} mm after the classic UMBmark "
                             "correction ({:.1f}x smaller; 3 SEM = {:.2f} mm).{}",
                             emax, after, emax / std::max(after, 1e-9), three_sem, shown_note),
                 r.evaluation->second_pass_worthwhile ? io::HtmlReport::Level::kWarn : io::HtmlReport::Level::kGood);
  } else {
    rep.Headline(fmt::format("Correction worthwhile: E_max,syst = {:.2f} mm stands out of the scatter (3 SEM = {:.2f} mm).",
                             emax, three_sem),
                 io::HtmlReport::Level::kGood);
  }
}

// The --report page of one calibration: headline, what to do next, the
// numbers (parameters with intervals when refined, centres of gravity,
// E_d/E_b, evaluation before/after, the held-out comparison), then the
// plots. About 85 lines: one page laid out top to bottom, each table a few
// lines; the headline and the held-out section are their own helpers.
std::string CalibrationReportHtml(const nlohmann::json& j, const CalibrateJobResult& r, const std::string& plot_svg,
                                  const std::string& which, const RobotParams& chosen) {
  const UmbmarkSummary& s = r.umbmark;
  io::HtmlReport rep("umbmark calibrate", r.label);
  ReportHeadline(rep, r, which);
  std::vector<std::string> steps;
  if (s.compensation_worthwhile) {
    steps.push_back(fmt::format("Set the odometry to the {} parameters: wheelbase {:.6f} m, left wheel diameter {:.6f} m, "
                                "right wheel diameter {:.6f} m (or load the multipliers of --ros2 into diff_drive_controller).",
                                which, chosen.wheelbase_m, chosen.wheel_diameter_left_m, chosen.wheel_diameter_right_m));
    steps.push_back("Drive a few new squares with the new parameters and run `umbmark calibrate` on them: a second pass "
                    "is relative to the new parameters and composes.");
  } else {
    steps.push_back("Keep the current parameters; drive more runs per direction if you expected a systematic error (the "
                    "SEM shrinks with the square root of the number of runs).");
  }
  if (r.evaluation && r.evaluation->second_pass_worthwhile)
    steps.push_back("After correction the systematic error still stands out of the scatter: run a second calibration pass.");
  if (r.refine_failure)
    steps.push_back(fmt::format("The refined fit failed its quality gate ({}); the classic result above stands.",
                                r.refine_failure->what()));
  rep.NextSteps(steps);
  std::vector<std::string> warnings;
  if (j.contains("warnings") && j["warnings"].is_array())
    for (const auto& w : j["warnings"]) warnings.push_back(w.get<std::string>());
  for (const auto& f : s.runs)
    if (f.outlier && !f.rejected)
      warnings.push_back(fmt::format("run {} ({}) is an outlier (robust score {:.1f}) but was kept; --reject-outliers drops it",
                                     f.run, f.direction, f.score.value_or(0.0)));
  rep.Warnings(warnings);

  rep.Heading("Parameters");
  std::vector<std::vector<std::string>> rows;
  const char* keys[3] = {"wheelbase_m", "wheel_diameter_left_m", "wheel_diameter_right_m"};
  const char* names[3] = {"wheelbase [m]", "left wheel diameter [m]", "right wheel diameter [m]"};
  const double rec[3] = {s.recorded.wheelbase_m, s.recorded.wheel_diameter_left_m, s.recorded.wheel_diameter_right_m};
  const double umb[3] = {s.corrected.wheelbase_m, s.corrected.wheel_diameter_left_m, s.corrected.wheel_diameter_right_m};
  const bool refined = j.contains("refined") && j["refined"].contains("parameters");
  for (int k = 0; k < 3; ++k) {
    std::vector<std::string> row = {names[k], fmt::format("{:.6f}", rec[k]), fmt::format("{:.6f}", umb[k])};
    if (refined) {
      const double v = j["refined"]["parameters"][keys[k]].get<double>();
      const double sd = std::sqrt(std::max(0.0, j["refined"]["covariance"][k][k].get<double>()));
      row.push_back(fmt::format("{:.6f} [{:.6f}, {:.6f}]", v, v - 1.96 * sd, v + 1.96 * sd));
    }
    rows.push_back(row);
  }
  std::vector<std::string> header = {"parameter", "recorded (used by the runs)", "UMBmark"};
  if (refined) header.push_back("refined, 95% interval");
  rep.Table(header, rows);
  rep.Table({"quantity", "value"},
            {{"E_d (diameter ratio error, eq. 4.22)", fmt::format("{:.6f}", s.selected.E_d)},
             {"E_b (wheelbase error, eq. 4.24)", fmt::format("{:.6f}", s.selected.E_b)},
             {"c_L, c_R (diameter factors, eqs. 4.31-4.32)", fmt::format("{:.6f}, {:.6f}", s.c_L, s.c_R)},
             {"alpha, beta", fmt::format("{:+.4f} deg, {:+.4f} deg", Rad2Deg(s.selected.alpha_rad), Rad2Deg(s.selected.beta_rad))},
             {"estimator; square side", fmt::format("{}; {} m", UmbmarkEstimatorToString(s.estimator), s.side_m)}});
  rep.Heading("Return errors: centres of gravity (eq. 3.2)");
  rows.clear();
  for (const auto* c : {&s.cw, &s.ccw})
    rows.push_back({c == &s.cw ? "cw" : "ccw", std::to_string(c->n), fmt::format("{:+.2f}", c->x_cg_m * 1e3),
                    fmt::format("{:+.2f}", c->y_cg_m * 1e3), fmt::format("{:.2f}", c->r_cg_m * 1e3),
                    fmt::format("{:.2f}", c->sigma_m * 1e3), fmt::format("{:.2f}", c->sem_m * 1e3)});
  rep.Table({"direction", "runs", "x_cg [mm]", "y_cg [mm]", "r_cg [mm]", "sigma [mm]", "SEM [mm]"}, rows);
  if (r.evaluation) {
    rep.Heading("Odometry vs ground truth on the same runs");
    auto row = [](const std::string& name, const EvaluationSummary& e) {
      return std::vector<std::string>{name, fmt::format("{:.2f}", e.mean_final_position_error_m * 1e3),
                                      fmt::format("{:.2f}", e.max_max_position_error_m * 1e3),
                                      fmt::format("{:.3f}", Rad2Deg(e.mean_final_heading_error_rad)),
                                      fmt::format("{:.3f}", Rad2Deg(e.max_max_heading_error_rad))};
    };
    rows = {row("recorded parameters", r.evaluation->before), row("UMBmark parameters", r.evaluation->after)};
    if (r.refined_evaluation) rows.push_back(row("refined parameters", *r.refined_evaluation));
    rep.Table({"odometry with", "final position error, mean [mm]", "max position error [mm]",
               "final heading error, mean [deg]", "max heading error [deg]"},
              rows);
  }
  HeldoutSection(rep, j);
  rep.Heading("Plots");
  rep.Figure(plot_svg, fmt::format("Return errors before and after correction with the {} parameters, on one scale; "
                                   "then every run's path (up to 48; the largest final errors after correction marked).",
                                   which));
  return rep.Render();
}

/// The job options of the command line (--refine's RefineOptions checked).
CalibrateJobOptions JobOptions(const CalibrateOptions& o) {
  CalibrateJobOptions jo;
  jo.umbmark.estimator = *UmbmarkEstimatorFromString(o.estimator);
  jo.umbmark.ed_with_corrected_wheelbase = o.ed_wheelbase == "corrected";
  jo.umbmark.exclude_runs = o.exclude_runs;
  jo.umbmark.reject_outliers = o.reject_outliers;
  jo.umbmark.outlier_threshold = o.outlier_threshold;
  jo.integrator = *IntegratorFromString(o.integrator);
  jo.keep_classic_on_refine_failure = true;
  // The full-path fits' settings: used by --refine and, without it, by the
  // held-out comparison on trajectory input (heldout.hpp).
  {
    RefineOptions ro;
    auto has = [](const std::vector<std::string>& v, const char* name) {
      return std::find(v.begin(), v.end(), name) != v.end();
    };
    if (has(o.fix, "scale") && has(o.free, "scale")) throw InvalidOptions("--fix scale and --free scale contradict each other");
    if (has(o.fix, "scale")) ro.scale = ScaleMode::kFixed;
    if (has(o.free, "scale")) ro.scale = ScaleMode::kFree;
    ro.loss = *RobustLossFromString(o.loss);
    ro.loss_scale_m = o.loss_scale_m;
    ro.samples_per_run = o.samples_per_run;
    ro.sampling = *PoseSamplingFromString(o.sampling);
    ro.start_pose = *StartPoseFromString(o.start_pose);
    ro.heading_weight = o.heading_weight;
    if (auto err = ro.Check(); !err.empty()) throw InvalidOptions(err);
    jo.compare_refine = ro;
    if (o.refine) jo.refine = ro;
  }
  return jo;
}

/// Faults the data show before any fit: swapped encoder channels (exit 3)
/// and unit mix-ups (exit 1).
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
  if (auto problem = CheckReturnErrorScale(in.errors, in.side_m); !problem.empty())
    throw InputError(in.label, problem);
}

/// Output safety: no output may be an input or another output.
void CheckOutputs(const CalibrateOptions& o) {
  io::OutputSet& outs = CommandOutputs();
  RegisterInputs(o.inputs, &o.robot);
  outs.AddOutput("--json", o.json.path);
  outs.AddOutput("--ros2", o.ros2);
  outs.AddOutput("--plot", o.plot);
  outs.AddOutput("--report", o.report);
  outs.Check();
}

/// A calibration unit's result that passed the plausibility gates (their
/// warnings kept for the output).
struct FittedUnit {
  CalibrateJobResult result;
  PlausibilityReport gate;
};

/// What the command says about a fitted unit: the held-out comparison of the
/// methods, the calibration the outputs use (--use), the check of the
/// centres of gravity against the model, and the warnings.
struct UnitAssessment {
  HeldoutComparison heldout;
  Chosen chosen;
  ModelCheck check;
  std::vector<std::string> warnings;
};

// `ground_truth_source`: the manifest's [ground_truth] source ("scan": the
// overall scale of fitted methods is the lidar's, ScaleForScanGroundTruth).
UnitAssessment Assess(const CalibrateInput& in, const FittedUnit& f, const CalibrateOptions& o,
                      const CalibrateJobOptions& jo, const std::string& ground_truth_source) {
  const CalibrateJobResult& r = f.result;
  HeldoutComparison heldout = o.no_heldout ? SkippedHeldout() : CompareMethodsHeldout(in, jo, r);
  Chosen chosen =
      ScaleForScanGroundTruth(ChooseParameters(r, heldout, o.use), ground_truth_source, o.scan_range_scale, r.umbmark.recorded);
  if (ground_truth_source == "scan") {
    heldout.notes.push_back("the ground truth is a lidar's scans (manifest [ground_truth] source = \"scan\"): a method "
                            "fitting the overall wheel scale fits the lidar's range scale; " + chosen.scale_note);
    if (!chosen.scale_note.empty()) chosen.why += "; " + chosen.scale_note;
  }
  const ModelCheck check = CheckCentresAgainstModel(in, r.umbmark.runs, r.refined ? r.refined->refined : r.umbmark.corrected,
                                                    jo.refine ? jo.refine->final_turn : true);
  std::vector<std::string> warnings = TrustWarnings(r, heldout, check);
  for (auto& m : planning::AdviseCalibration(in, chosen.parameters).messages) warnings.push_back(std::move(m));
  warnings.insert(warnings.end(), f.gate.warnings.begin(), f.gate.warnings.end());
  if (r.refined && in.trajectories && !HasInteriorGroundTruth(*in.trajectories)) {
    warnings.push_back("ground truth only at the first and last sample of each run: the refined fit used the "
                       "return errors (commanded-square model), as for endpoint data, not the path geometry");
  }
  return {std::move(heldout), std::move(chosen), check, std::move(warnings)};
}

// One `calibrate` command, in steps: Load each input into calibration units,
// Fit and gate each unit, Conclude it (assess, write its outputs, print),
// then the summary table and the JSON. With one input, errors propagate
// (exit 1, or 3 for a quality gate); with several (a batch), a failing input
// or unit is reported, recorded and skipped, and the exit status is the
// worst at the end. The members are the batch state the steps share.
class CalibrateBatch {
 public:
  CalibrateBatch(const CalibrateOptions& o, CalibrateJobOptions jo);
  int Run();

 private:
  struct Row {
    std::string label;
    std::optional<CalibrateJobResult> result;
    std::string error;
  };
  std::optional<std::vector<CalibrateInput>> Load(const std::string& path);
  std::optional<FittedUnit> Fit(const CalibrateInput& in);
  void Conclude(const std::string& path, const CalibrateInput& in, bool several, FittedUnit f);
  std::string UniqueTag(const std::string& path, const CalibrateInput& in);
  void WriteOutputs(const CalibrateInput& in, const CalibrateJobResult& r, const UnitAssessment& a,
                    const std::string& tag, bool several);
  void PrintSummaryTable() const;
  void RecordFailure(const std::string& label, const std::string& what, int code);

  const CalibrateOptions& o_;
  CalibrateJobOptions jo_;
  const bool batch_;
  nlohmann::json results_ = nlohmann::json::array();  ///< each unit's JSON, only when --json asks for it
  std::vector<Row> rows_;
  std::vector<std::string> all_warnings_;
  std::vector<std::string> written_;  ///< "path (what)"
  std::set<std::string> tags_used_;
  int status_ = 0;
  Progress progress_;
  double done_ = 0.0;
};

CalibrateBatch::CalibrateBatch(const CalibrateOptions& o, CalibrateJobOptions jo)
    : o_(o),
      jo_(std::move(jo)),
      batch_(o.inputs.size() > 1),
      progress_(fmt::format("calibrating {} inputs", o.inputs.size()), static_cast<double>(o.inputs.size())) {
  // Within an input, the held-out comparison (the long part) moves the line
  // by its folds.
  jo_.progress = [this](double folds_done, double folds) {
    progress_.Update(done_ - 1.0 + (folds > 0.0 ? folds_done / folds : 1.0));
  };
}

int CalibrateBatch::Run() {
  for (const auto& path : o_.inputs) {
    progress_.Update(done_++);
    const std::optional<std::vector<CalibrateInput>> inputs = Load(path);
    if (!inputs) continue;
    const bool several = batch_ || inputs->size() > 1;
    for (const auto& in : *inputs) {
      if (std::optional<FittedUnit> fitted = Fit(in)) Conclude(path, in, several, std::move(*fitted));
    }
  }
  if (o_.json.PrintText() && rows_.size() > 1) PrintSummaryTable();
  // (results_ holds the JSON of each unit only when --json asks for it.)
  const bool single = rows_.size() == 1 && rows_.front().result && !results_.empty();
  o_.json.EmitAndListOutputs(
      single ? results_.front()
             : nlohmann::json{{"results", results_}, {"failed", status_ != 0}, {"warnings", all_warnings_}},
      written_);
  return status_;
}

/// A failed unit of a batch: a row, a JSON entry and the worst exit status.
void CalibrateBatch::RecordFailure(const std::string& label, const std::string& what, int code) {
  rows_.push_back({label, std::nullopt, what});
  results_.push_back({{"input", label}, {"error", what}});
  status_ = std::max(status_, code);
}

/// The input's calibration units; nullopt when a batch input cannot be read
/// (reported and recorded).
std::optional<std::vector<CalibrateInput>> CalibrateBatch::Load(const std::string& path) {
  try {
    return LoadInputs(path, o_, jo_.integrator);
  } catch (const InputError& e) {
    if (!batch_) throw;
    fmt::print(stderr, "{}\n", e.what());
    RecordFailure(path, e.what(), 1);
    return std::nullopt;
  }
}

/// Checks the data, calibrates the unit and applies the plausibility gates;
/// nullopt when a batch unit fails (reported and recorded).
std::optional<FittedUnit> CalibrateBatch::Fit(const CalibrateInput& in) {
  FittedUnit f;
  try {
    CheckDataBeforeFit(in);
    f.result = RunCalibrateJob(in, jo_);
    // Plausibility gates: never print or write an impossible result.
    f.gate = CheckUmbmarkPlausibility(f.result.umbmark);
    if (f.result.refined) CheckRefinedPlausibility(f.result.umbmark.recorded, f.result.refined->refined, f.gate);
    if (!f.gate.ok()) throw QualityGateError(fmt::format("{}: implausible result: {}", in.label, f.gate.Message()));
  } catch (const RefineError& e) {
    // Print what is known (solver report, identifiability), then fail
    // the quality gate: exit 3, never numbers from a failed fit.
    fmt::print(stderr, "{}: refined calibration failed: {}\n{}", in.label, e.what(), RefineReport(e.summary()));
    if (!batch_) throw;
    RecordFailure(in.label, e.what(), 3);
    return std::nullopt;
  } catch (const QualityGateError& e) {
    if (!batch_) throw;
    fmt::print(stderr, "umbmark: quality gate failed: {}\n", e.what());
    RecordFailure(in.label, e.what(), 3);
    return std::nullopt;
  } catch (const InputError& e) {
    if (!batch_) throw;
    fmt::print(stderr, "{}\n", e.what());
    RecordFailure(in.label, e.what(), 1);
    return std::nullopt;
  }
  return f;
}

/// A fitted unit: assessed, its outputs written, printed (or its warnings on
/// stderr), its JSON and summary row kept.
void CalibrateBatch::Conclude(const std::string& path, const CalibrateInput& in, bool several, FittedUnit f) {
  const UnitAssessment a = Assess(in, f, o_, jo_, io::IsManifestPath(path) ? io::ReadGroundTruthSource(path) : std::string());
  CalibrateJobResult& r = f.result;
  WriteOutputs(in, r, a, UniqueTag(path, in), several);
  if (o_.json.PrintText()) {
    PrintResult(r);
    PrintHeldout(a.heldout, a.chosen, a.warnings, o_);
    fmt::print("\n");
  } else {
    for (const auto& w : a.warnings) fmt::print(stderr, "{}: warning: {}\n", in.label, w);
  }
  if (r.refine_failure) {
    // The classic result stands (printed and written); the refined fit
    // failed its quality gate: say so once, with the solver's report.
    fmt::print(stderr, "umbmark: quality gate failed: {}: refined calibration failed: {}\n  solver: {}\n", in.label,
               r.refine_failure->what(), r.refine_failure->summary().solver.brief_report);
    status_ = std::max(status_, 3);
  }
  for (const auto& w : a.warnings) all_warnings_.push_back(batch_ ? in.label + ": " + w : w);
  // The JSON document only when asked for: with a million runs it is
  // the largest thing the command builds.
  if (!o_.json.path.empty()) results_.push_back(JsonResult(in, r, o_, a.heldout, a.check, a.chosen, a.warnings));
  rows_.push_back({in.label, std::move(r), ""});
}

/// The unit's dataset tag (DatasetTag), numbered from 2 when already used.
std::string CalibrateBatch::UniqueTag(const std::string& path, const CalibrateInput& in) {
  std::string tag = DatasetTag(path, in);
  for (int k = 2; !tags_used_.insert(tag).second; ++k) tag = fmt::format("{}-{}", DatasetTag(path, in), k);
  return tag;
}

/// --ros2, --plot and --report of one unit (tagged with the dataset when the
/// command has several units).
void CalibrateBatch::WriteOutputs(const CalibrateInput& in, const CalibrateJobResult& r, const UnitAssessment& a,
                                  const std::string& tag, bool several) {
  io::OutputSet& outs = CommandOutputs();
  if (!o_.ros2.empty()) {
    const std::string file = several ? TaggedPath(o_.ros2, tag) : o_.ros2;
    outs.Write(file, Ros2Parameters(r, a.chosen, o_.controller));
    written_.push_back(file + " (ros2_control parameters)");
  }
  // The plot and the report show the calibration --use selects (by
  // default the recommended one), and say which.
  const RobotParams& shown = a.chosen.parameters;
  const std::string& which = a.chosen.method;
  std::string svg;
  if (!o_.plot.empty() || !o_.report.empty()) svg = CalibrationPlotSvg(in, r, jo_.integrator, shown, which);
  if (!o_.plot.empty()) {
    const std::string file = several ? TaggedPath(o_.plot, tag) : o_.plot;
    outs.Write(file, svg);
    written_.push_back(file + " (plot: " + which + ")");
  }
  if (!o_.report.empty()) {
    const std::string file = several ? TaggedPath(o_.report, tag) : o_.report;
    outs.Write(file, CalibrationReportHtml(JsonResult(in, r, o_, a.heldout, a.check, a.chosen, a.warnings), r, svg,
                                           which, shown));
    written_.push_back(file + " (HTML report)");
  }
}

/// The batch's summary table: one line per unit (FAILED with the reason).
void CalibrateBatch::PrintSummaryTable() const {
  fmt::print("Summary ({} calibrations)\n", rows_.size());
  fmt::print("  {:<40} {:>10} {:>10} {:>11} {:>11} {:>11} {:>10} {:>10}\n", "input", "E_d", "E_b", "wheelbase_m",
             "D_left_m", "D_right_m", "Emax_mm", "after_mm");
  for (const auto& row : rows_) {
    if (!row.result) {
      fmt::print("  {:<40} FAILED: {}\n", row.label, row.error);
      continue;
    }
    const auto& s = row.result->umbmark;
    const std::string after =
        row.result->evaluation ? fmt::format("{:.2f}", row.result->evaluation->E_max_syst_m * 1e3) : "-";
    fmt::print("  {:<40} {:>10.6f} {:>10.6f} {:>11.6f} {:>11.6f} {:>11.6f} {:>10.2f} {:>10}\n", row.label,
               s.selected.E_d, s.selected.E_b, s.corrected.wheelbase_m, s.corrected.wheel_diameter_left_m,
               s.corrected.wheel_diameter_right_m, s.E_max_syst_m * 1e3, after);
  }
}

int RunCalibrate(const CalibrateOptions& o) {
  if (o.use == "refined" && !o.refine) throw InvalidOptions("--use refined needs --refine");
  CalibrateJobOptions jo = JobOptions(o);
  CheckOutputs(o);
  CalibrateBatch command(o, std::move(jo));
  return command.Run();
}

}  // namespace

Command SetupCalibrate(CLI::App& parent) {
  auto opts = std::make_shared<CalibrateOptions>();
  auto* app = parent.add_subcommand("calibrate", "UMBmark calibration from CW/CCW square runs");
  app->add_option("DATA", opts->inputs, "Endpoint or trajectory CSV, or campaign manifest (.toml); several = batch")
      ->required();
  opts->robot.Bind(*app);
  app->add_option("--side", opts->side_m, "Square side L [m] (required for CSV input)")->check(Plausible("side_m"));
  app->add_option("--estimator", opts->estimator, "alpha/beta from x (4.20a, 4.24a), y (4.20b, 4.24b) or their mean")
      ->check(CLI::IsMember({"x", "y", "mean"}))
      ->capture_default_str();
  app->add_option("--integrator", opts->integrator,
                  "Odometry from ticks: exact arc, or midpoint (as the OptiOdom reference implementation)")
      ->check(CLI::IsMember({"arc", "midpoint"}))
      ->capture_default_str();
  app->add_option("--ed-wheelbase", opts->ed_wheelbase, "Wheelbase used in eq. 4.22 for E_d")
      ->check(CLI::IsMember({"corrected", "recorded"}))
      ->capture_default_str();
  app->add_option("--exclude-runs", opts->exclude_runs, "Run ids to leave out (listed in the output)")->delimiter(',');
  app->add_flag("--reject-outliers", opts->reject_outliers, "Drop runs flagged as outliers (listed in the output)");
  app->add_option("--outlier-threshold", opts->outlier_threshold, "Robust score above which a run is flagged")
      ->check(Positive())
      ->capture_default_str();
  opts->json.Bind(*app);
  app->add_option("--ros2", opts->ros2,
                  "Write a ros2_control diff_drive_controller parameter file (YAML for ros2 param load) of the --use "
                  "calibration");
  app->add_option("--scan-range-scale", opts->scan_range_scale,
                  "Scan ground truth (import rosbag2 --scan): the lidar's range scale from a range calibration "
                  "(measured range / true distance, e.g. 1.01); the --ros2 multipliers' overall scale then comes from "
                  "the scans' distances divided by it, instead of being kept")
      ->check(NumberIn(0.5, 2.0));
  app->add_option("--controller", opts->controller, "Controller name at the top of the --ros2 file")
      ->capture_default_str();
  app->add_option("--plot", opts->plot,
                  "Write an SVG: return errors before/after (the --use calibration) on one scale, centres of gravity "
                  "with SEM ellipses, E_max,syst, and each run's path");
  app->add_flag("--no-heldout", opts->no_heldout,
                "Skip the held-out comparison of the methods (it calibrates every method once per fold; "
                "JSON `recommended` and `heldout_error` say \"skipped\", and --use recommended takes the classic "
                "result). Default: compare");
  app->add_option("--use", opts->use,
                  "Calibration --ros2 and --plot use: the recommended one (held-out comparison: "
                  "docs/calibration-comparison.md), classic UMBmark, or refined (needs --refine)")
      ->check(CLI::IsMember({"recommended", "classic", "refined"}))
      ->capture_default_str();
  app->add_option("--report", opts->report, "Write a self-contained HTML report (result, next steps, plots)");
  app->add_flag("--refine", opts->refine,
                "Add the exact Ceres fit (every run, full path geometry for trajectories) with covariance and 95% intervals");
  app->add_option("--fix", opts->fix, "With --refine: hold these parameters at their recorded values (scale)")
      ->delimiter(',')
      ->check(CLI::IsMember({"scale"}));
  app->add_option("--free", opts->free, "With --refine: estimate these parameters (scale); fails if the data do not determine them")
      ->delimiter(',')
      ->check(CLI::IsMember({"scale"}));
  app->add_option("--loss", opts->loss, "With --refine on trajectories: robust loss per sampled pose")
      ->check(CLI::IsMember({"huber", "cauchy", "none"}))
      ->capture_default_str();
  app->add_option("--loss-scale", opts->loss_scale_m, "Robust loss scale [m]")->check(Positive())->capture_default_str();
  app->add_flag("--per-experiment", opts->per_experiment,
                "A manifest with several square experiments: one calibration per experiment (default: pooled into one)");
  app->add_option("--samples-per-run", opts->samples_per_run, "Poses sampled per trajectory run (evenly in travel)")
      ->check(NumberIn(2, 100000))
      ->capture_default_str();
  app->add_option("--sampling", opts->sampling,
                  "With --refine on trajectories: poses per run (--samples-per-run) or every sample with ground truth")
      ->check(CLI::IsMember({"per_run", "every_sample"}))
      ->capture_default_str();
  app->add_option("--start-pose", opts->start_pose,
                  "With --refine on trajectories: each run's frame at its first ground-truth sample, the mean over "
                  "its initial standstill, fitted (profiled out per run), or session_frame (first sample, one "
                  "ground-truth frame error per recording session fitted jointly; docs/calibration-comparison.md)")
      ->check(CLI::IsMember({"first_sample", "standstill_mean", "fitted", "session_frame"}))
      ->capture_default_str();
  app->add_option("--heading-weight", opts->heading_weight,
                  "With --refine on trajectories: heading residual weight, in wheelbases per radian (0 = position only)")
      ->check(NonNegative())
      ->capture_default_str();
  return {app, [opts] { return RunCalibrate(*opts); }};
}

}  // namespace umbmark::cli
