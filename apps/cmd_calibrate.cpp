// `umbmark calibrate DATA... --robot R.toml --side S [--estimator x|y|mean]`:
// classic UMBmark (Borenstein & Feng) from CW/CCW square runs, endpoint or
// trajectory CSV, or campaign manifests (their square experiments). Several
// inputs give one result each plus a summary table (factory batch use).
// The command is the library's api::Calibrate (lib/api/calibrate.hpp):
// this file binds the flags to its options, and prints.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "api/calibrate.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "core/angles.hpp"
#include "core/errors.hpp"
#include "progress.hpp"

namespace umbmark::cli {

namespace {

/// The command line's options: the library's, and where the JSON goes.
struct CalibrateFlags {
  api::CalibrateOptions o;
  JsonFlag json;
};

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

void PrintHeldout(const HeldoutComparison& h, const api::OutputsUse& chosen, const std::vector<std::string>& warnings,
                  bool files) {
  if (h.scheme == "skipped") {
    fmt::print("Which calibration to trust: not compared (--no-heldout); run without it for the held-out "
               "prediction error of each method\n");
  } else {
    PrintHeldoutTable(h);
  }
  if (files) {
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

/// The batch's summary table: one line per unit (FAILED with the reason).
void PrintSummaryTable(const api::CalibrateResult& result) {
  fmt::print("Summary ({} calibrations)\n", result.results.size());
  fmt::print("  {:<40} {:>10} {:>10} {:>11} {:>11} {:>11} {:>10} {:>10}\n", "input", "E_d", "E_b", "wheelbase_m",
             "D_left_m", "D_right_m", "Emax_mm", "after_mm");
  for (const auto& row : result.results) {
    if (!row.result) {
      fmt::print("  {:<40} FAILED: {}\n", row.input, row.error);
      continue;
    }
    const CalibrateJobResult& job = row.result->job;
    const auto& s = job.umbmark;
    const std::string after = job.evaluation ? fmt::format("{:.2f}", job.evaluation->E_max_syst_m * 1e3) : "-";
    fmt::print("  {:<40} {:>10.6f} {:>10.6f} {:>11.6f} {:>11.6f} {:>11.6f} {:>10.2f} {:>10}\n", row.input,
               s.selected.E_d, s.selected.E_b, s.corrected.wheelbase_m, s.corrected.wheel_diameter_left_m,
               s.corrected.wheel_diameter_right_m, s.E_max_syst_m * 1e3, after);
  }
}

/// What the command prints of one unit as the batch goes: the result and the
/// held-out table (or, with `--json -`, the warnings on stderr), a failure's
/// message, a refined fit's failure while the classic result stands.
void PrintOutcome(const api::CalibrateOutcome& out, bool text, bool files) {
  if (!out.result) {
    const bool refine = out.failure == api::CalibrateOutcome::Failure::kRefine;
    fmt::print(stderr, "{}{}", out.Message(), refine ? "" : "\n");
    return;
  }
  const api::CalibrateUnitResult& u = *out.result;
  if (text) {
    PrintResult(u.job);
    PrintHeldout(u.heldout, u.outputs_use, u.warnings, files);
    fmt::print("\n");
  } else {
    for (const auto& w : u.warnings) fmt::print(stderr, "{}: warning: {}\n", u.input, w);
  }
  // The classic result stands (printed and written); the refined fit
  // failed its quality gate: said once, with the solver's report.
  if (u.refine_error) fmt::print(stderr, "{}\n", out.Message());
}

int RunCalibrate(CalibrateFlags& f) {
  io::OutputSet& outs = CommandOutputs();
  outs.AddOutput("--json", f.json.path);
  f.o.outputs = &outs;
  const std::size_t count = f.o.inputs.size();
  Progress progress(fmt::format("calibrating {} inputs", count), static_cast<double>(count));
  f.o.progress = progress.Callback();
  const bool text = f.json.PrintText(), files = !f.o.ros2.empty() || !f.o.plot.empty();
  const api::CalibrateResult r =
      api::Calibrate(std::move(f.o), [&](const api::CalibrateOutcome& out) { PrintOutcome(out, text, files); });
  if (text && r.results.size() > 1) PrintSummaryTable(r);
  // The JSON document only when asked for: with a million runs it is the
  // largest thing the command builds.
  f.json.EmitAndListOutputs(f.json.path.empty() ? nlohmann::json() : api::ToJson(r), r.written);
  return r.exit_status;
}

}  // namespace

Command SetupCalibrate(CLI::App& parent) {
  auto opts = std::make_shared<CalibrateFlags>();
  auto* app = parent.add_subcommand("calibrate", "UMBmark calibration from CW/CCW square runs");
  app->add_option("DATA", opts->o.inputs, "Endpoint or trajectory CSV, or campaign manifest (.toml); several = batch")
      ->required();
  BindRobot(*app, opts->o.robot);
  app->add_option("--side", opts->o.side_m, "Square side L [m] (required for CSV input)")->check(Plausible("side_m"));
  app->add_option("--estimator", opts->o.estimator, "alpha/beta from x (4.20a, 4.24a), y (4.20b, 4.24b) or their mean")
      ->check(CLI::IsMember({"x", "y", "mean"}))
      ->capture_default_str();
  app->add_option("--integrator", opts->o.integrator,
                  "Odometry from ticks: exact arc, or midpoint (as the OptiOdom reference implementation)")
      ->check(CLI::IsMember({"arc", "midpoint"}))
      ->capture_default_str();
  app->add_option("--ed-wheelbase", opts->o.ed_wheelbase, "Wheelbase used in eq. 4.22 for E_d")
      ->check(CLI::IsMember({"corrected", "recorded"}))
      ->capture_default_str();
  app->add_option("--exclude-runs", opts->o.exclude_runs, "Run ids to leave out (listed in the output)")->delimiter(',');
  app->add_flag("--reject-outliers", opts->o.reject_outliers, "Drop runs flagged as outliers (listed in the output)");
  app->add_option("--outlier-threshold", opts->o.outlier_threshold, "Robust score above which a run is flagged")
      ->check(Positive())
      ->capture_default_str();
  opts->json.Bind(*app);
  app->add_option("--ros2", opts->o.ros2,
                  "Write a ros2_control diff_drive_controller parameter file (YAML for ros2 param load) of the --use "
                  "calibration");
  app->add_option("--scan-range-scale", opts->o.scan_range_scale,
                  "Scan ground truth (import rosbag2 --scan): the lidar's range scale from a range calibration "
                  "(measured range / true distance, e.g. 1.01); the --ros2 multipliers' overall scale then comes from "
                  "the scans' distances divided by it, instead of being kept")
      ->check(NumberIn(0.5, 2.0));
  app->add_option("--controller", opts->o.controller, "Controller name at the top of the --ros2 file")
      ->capture_default_str();
  app->add_option("--plot", opts->o.plot,
                  "Write an SVG: return errors before/after (the --use calibration) on one scale, centres of gravity "
                  "with SEM ellipses, E_max,syst, and each run's path");
  app->add_flag("--no-heldout", opts->o.no_heldout,
                "Skip the held-out comparison of the methods (it calibrates every method once per fold; "
                "JSON `recommended` and `heldout_error` say \"skipped\", and --use recommended takes the classic "
                "result). Default: compare");
  app->add_option("--use", opts->o.use,
                  "Calibration --ros2 and --plot use: the recommended one (held-out comparison: "
                  "docs/calibration-comparison.md), classic UMBmark, or refined (needs --refine)")
      ->check(CLI::IsMember({"recommended", "classic", "refined"}))
      ->capture_default_str();
  app->add_option("--report", opts->o.report, "Write a self-contained HTML report (result, next steps, plots)");
  app->add_flag("--refine", opts->o.refine,
                "Add the exact Ceres fit (every run, full path geometry for trajectories) with covariance and 95% intervals");
  app->add_option("--fix", opts->o.fix, "With --refine: hold these parameters at their recorded values (scale)")
      ->delimiter(',')
      ->check(CLI::IsMember({"scale"}));
  app->add_option("--free", opts->o.free, "With --refine: estimate these parameters (scale); fails if the data do not determine them")
      ->delimiter(',')
      ->check(CLI::IsMember({"scale"}));
  app->add_option("--loss", opts->o.loss, "With --refine on trajectories: robust loss per sampled pose")
      ->check(CLI::IsMember({"huber", "cauchy", "none"}))
      ->capture_default_str();
  app->add_option("--loss-scale", opts->o.loss_scale_m, "Robust loss scale [m]")->check(Positive())->capture_default_str();
  app->add_flag("--per-experiment", opts->o.per_experiment,
                "A manifest with several square experiments: one calibration per experiment (default: pooled into one)");
  app->add_option("--samples-per-run", opts->o.samples_per_run, "Poses sampled per trajectory run (evenly in travel)")
      ->check(NumberIn(2, 100000))
      ->capture_default_str();
  app->add_option("--sampling", opts->o.sampling,
                  "With --refine on trajectories: poses per run (--samples-per-run) or every sample with ground truth")
      ->check(CLI::IsMember({"per_run", "every_sample"}))
      ->capture_default_str();
  app->add_option("--start-pose", opts->o.start_pose,
                  "With --refine on trajectories: each run's frame at its first ground-truth sample, the mean over "
                  "its initial standstill, fitted (profiled out per run), or session_frame (first sample, one "
                  "ground-truth frame error per recording session fitted jointly; docs/calibration-comparison.md)")
      ->check(CLI::IsMember({"first_sample", "standstill_mean", "fitted", "session_frame"}))
      ->capture_default_str();
  app->add_option("--heading-weight", opts->o.heading_weight,
                  "With --refine on trajectories: heading residual weight, in wheelbases per radian (0 = position only)")
      ->check(NonNegative())
      ->capture_default_str();
  return {app, [opts] { return RunCalibrate(*opts); }};
}

}  // namespace umbmark::cli
