// The files `umbmark calibrate` writes besides its JSON (see calibrate.hpp):
// the ros2_control parameter file (--ros2) and the HTML report (--report).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "api/calibrate.hpp"
#include "core/angles.hpp"
#include "formats/ros2_params.hpp"
#include "report/html_report.hpp"

namespace umbmark::api {

namespace {

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

}  // namespace

// diff_drive_controller multipliers of the chosen calibration (--use): each
// parameter relative to the one the runs were recorded with.
std::string Ros2Parameters(const CalibrateUnitResult& unit, const std::string& controller) {
  const OutputsUse& chosen = unit.outputs_use;
  io::DiffDriveMultipliers m;
  m.wheel_separation_multiplier = chosen.separation;
  m.left_wheel_radius_multiplier = chosen.left;
  m.right_wheel_radius_multiplier = chosen.right;
  return io::FormatDiffDriveCalibration(
      controller, m, unit.recorded_parameters,
      {fmt::format("ros2_control diff_drive_controller parameters from umbmark calibrate: {} ({})", chosen.method,
                   unit.input),
       chosen.scale_note.empty() ? std::string("overall scale: fitted to the ground truth's distances")
                                 : "overall scale: " + chosen.scale_note,
       "Load with: ros2 param load /" + controller + " FILE (or add to the controller's --param-file list)"});
}

// The --report page of one calibration: headline, what to do next, the
// numbers (parameters with intervals when refined, centres of gravity,
// E_d/E_b, evaluation before/after, the held-out comparison), then the
// plots. About 85 lines: one page laid out top to bottom, each table a few
// lines; the headline and the held-out section are their own helpers.
std::string CalibrationReportHtml(const CalibrateUnitResult& unit, const std::string& plot_svg) {
  const nlohmann::json j = ToJson(unit);
  const CalibrateJobResult& r = unit.job;
  const std::string& which = unit.outputs_use.method;
  const RobotParams& chosen = unit.outputs_use.parameters;
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

}  // namespace umbmark::api
