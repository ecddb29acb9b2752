// `umbmark evaluate DATA... --robot R.toml [--params CAL.json]`: errors of
// odometry against ground truth along trajectories (any path shape) for the
// recorded parameters or a calibration, per run and over all runs. The
// command's logic is api::Evaluate (lib/api/evaluate.hpp); this file parses,
// calls it and prints.
#include <memory>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "api/evaluate.hpp"
#include "api/evaluate_report.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "core/angles.hpp"

namespace umbmark::cli {

namespace {

struct EvaluateOptions {
  std::vector<std::string> inputs;
  RobotFlags robot;
  std::string params_file;
  std::string integrator = "arc";
  JsonFlag json;
  std::string plot;
  std::string report;
};

void PrintSummary(const char* title, const EvaluationSummary& s) {
  fmt::print("{} ({} runs)\n", title, s.runs.size());
  fmt::print("  {:<44} {:>6} {:<10} {:>10} {:>10} {:>10} {:>10}\n", "experiment", "run", "direction", "final_mm",
             "max_mm", "final_deg", "max_deg");
  for (const auto& r : s.runs) {
    fmt::print("  {:<44} {:>6} {:<10} {:>10.2f} {:>10.2f} {:>10.3f} {:>10.3f}\n", r.experiment, r.run, r.direction,
               r.final_position_error_m * 1e3, r.max_position_error_m * 1e3, Rad2Deg(r.final_heading_error_rad),
               Rad2Deg(r.max_heading_error_rad));
  }
  fmt::print("  {:<62} {:>10.2f} {:>10.2f} {:>10.3f} {:>10.3f}\n", "mean", s.mean_final_position_error_m * 1e3,
             s.mean_max_position_error_m * 1e3, Rad2Deg(s.mean_final_heading_error_rad),
             Rad2Deg(s.mean_max_heading_error_rad));
  fmt::print("  {:<62} {:>10.2f} {:>10.2f} {:>10.3f} {:>10.3f}\n", "max", s.max_final_position_error_m * 1e3,
             s.max_max_position_error_m * 1e3, Rad2Deg(s.max_final_heading_error_rad),
             Rad2Deg(s.max_max_heading_error_rad));
}

int RunEvaluate(const EvaluateOptions& o) {
  io::OutputSet& outs = CommandOutputs();
  RegisterInputs(o.inputs, &o.robot);
  outs.AddInput(o.params_file);
  outs.AddOutput("--json", o.json.path);
  outs.AddOutput("--plot", o.plot);
  outs.AddOutput("--report", o.report);
  outs.Check();
  api::EvaluateOptions eo;
  eo.inputs = o.inputs;
  eo.robot = {o.robot.robot_file, o.robot.wheelbase_m, o.robot.diameter_left_m, o.robot.diameter_right_m,
              o.robot.ticks_per_rev};
  eo.params_file = o.params_file;
  eo.integrator = *IntegratorFromString(o.integrator);
  eo.keep_plot_runs = !o.plot.empty() || !o.report.empty();
  const api::EvaluateResult r = api::Evaluate(eo);
  if (o.json.PrintText()) {
    PrintSummary("Recorded parameters", r.Base());
    if (r.recorded) {
      fmt::print("\n");
      PrintSummary(fmt::format("Parameters from {}", o.params_file).c_str(), r.summary);
    }
    for (const auto& w : r.warnings) fmt::print("  WARNING: {}\n", w);
  } else {
    for (const auto& w : r.warnings) fmt::print(stderr, "warning: {}\n", w);
  }
  std::vector<std::string> written;
  std::string svg;
  if (eo.keep_plot_runs) svg = api::EvaluatePlotSvg(r);
  if (!o.plot.empty()) {
    outs.Write(o.plot, svg);
    written.push_back(o.plot + " (plot)");
  }
  if (!o.report.empty()) {
    outs.Write(o.report, api::EvaluateReportHtml(r, o.inputs, o.params_file, svg));
    written.push_back(o.report + " (HTML report)");
  }
  o.json.EmitAndListOutputs(api::ToJson(r), written);
  return 0;
}

}  // namespace

Command SetupEvaluate(CLI::App& parent) {
  auto opts = std::make_shared<EvaluateOptions>();
  auto* app = parent.add_subcommand("evaluate", "Odometry vs ground truth along trajectories, for any parameters");
  app->add_option("DATA", opts->inputs, "Trajectory CSV(s) or campaign manifest(s)")->required();
  opts->robot.Bind(*app);
  app->add_option("--params", opts->params_file, "Calibration JSON from `umbmark calibrate` (refined.parameters if present)");
  app->add_option("--integrator", opts->integrator, "Odometry from ticks: arc (exact) or midpoint")
      ->check(CLI::IsMember({"arc", "midpoint"}))
      ->capture_default_str();
  opts->json.Bind(*app);
  app->add_option("--plot", opts->plot,
                  "Write an SVG: position and heading error along the travelled distance per run, and the paths");
  app->add_option("--report", opts->report, "Write a self-contained HTML report (summary, per-run table, plots)");
  return {app, [opts] { return RunEvaluate(*opts); }};
}

}  // namespace umbmark::cli
