// `umbmark evaluate DATA... --robot R.toml [--params CAL.json]`: errors of
// odometry against ground truth along trajectories (any path shape) for the
// recorded parameters or a calibration, per run and over all runs.
#include <cmath>
#include <memory>
#include <set>
#include <variant>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "common.hpp"
#include "core/angles.hpp"
#include "core/errors.hpp"
#include "evaluation/run_track.hpp"
#include "io/atomic_write.hpp"
#include "io/data_file.hpp"
#include "io/params_json.hpp"
#include "io/manifest.hpp"
#include "io/svg_plot.hpp"

namespace umbmark::cli {

namespace {

struct EvaluateOptions {
  std::vector<std::string> inputs;
  RobotFlags robot;
  std::string params_file;
  std::string integrator = "arc";
  JsonFlag json;
  std::string plot;
};

/// One file to evaluate: a trajectory CSV, or one experiment of a manifest.
struct Source {
  std::string label;
  RobotParams recorded;
  std::string path;
  std::string manifest;  ///< the manifest it comes from (its endpoint files are skipped), or empty
};

/// The files to read, in order (manifests are read here, the data files not).
std::vector<Source> ListSources(const EvaluateOptions& o) {
  std::vector<Source> out;
  for (const auto& path : o.inputs) {
    if (io::IsManifestPath(path)) {
      const Manifest m = io::ReadManifest(path);
      const RobotParams robot = o.robot.Resolve(m.robot);
      int index = 0;
      for (const auto& e : m.experiments) {
        ++index;
        out.push_back({fmt::format("{}#{}:{}", path, index, ExperimentKindToString(e.kind)), robot, e.resolved_file,
                       path});
      }
    } else {
      out.push_back({path, o.robot.Resolve(), path, ""});
    }
  }
  return out;
}

/// A run kept for the plot, with the source it came from.
struct PlotRun {
  const Source* source;
  TrajectoryRun run;
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

/// Runs drawn in the --plot figure (the first ones; keeps it readable).
constexpr std::size_t kPlotRuns = 12;

std::string PlotSvg(const std::vector<PlotRun>& runs, const std::optional<RobotParams>& params, Integrator integ) {
  std::vector<std::string> parts;
  const double size = 380;
  double x = 60, y = 40;
  int col = 0;
  for (const auto& [source, run] : runs) {
    const Source& src = *source;
    io::SvgPanel p(x, y, size, size, fmt::format("{} run {}", src.label, run.run));
    const RunTrack before = TrackRun(run, src.path, src.recorded, src.recorded, integ);
    std::vector<io::SvgPoint> gt, od, od2, all;
    for (std::size_t i = 0; i < run.size(); ++i) {
      if (before.has_ground_truth[i]) gt.push_back({before.ground_truth[i].x, before.ground_truth[i].y});
      od.push_back({before.odometry[i].x, before.odometry[i].y});
    }
    all = gt;
    all.insert(all.end(), od.begin(), od.end());
    if (params) {
      const RunTrack after = TrackRun(run, src.path, *params, src.recorded, integ);
      for (const auto& q : after.odometry) od2.push_back({q.x, q.y});
      all.insert(all.end(), od2.begin(), od2.end());
    }
    p.FitExtent(all, true, true);
    p.Axes("x [m]", "y [m]");
    p.Polyline(gt, "#111", 2.0);
    p.Polyline(od, "#d62728", 1.2, "4,3");
    if (params) p.Polyline(od2, "#2ca02c", 1.2);
    std::vector<std::pair<std::string, std::string>> legend = {{"#111", "ground truth"},
                                                               {"#d62728", "odometry, recorded parameters"}};
    if (params) legend.push_back({"#2ca02c", "odometry, --params"});
    p.Legend(legend);
    parts.push_back(p.Render());
    if (++col == 3) {
      col = 0;
      x = 60;
      y += size + 60;
    } else {
      x += size + 60;
    }
  }
  const double rows = std::ceil(static_cast<double>(parts.size()) / 3.0);
  return io::SvgDocument(3 * (size + 60) + 40, rows * (size + 60) + 40, parts);
}

int RunEvaluate(const EvaluateOptions& o) {
  const Integrator integ = *IntegratorFromString(o.integrator);
  io::OutputSet& outs = CommandOutputs();
  RegisterInputs(o.inputs, &o.robot);
  outs.AddInput(o.params_file);
  outs.AddOutput("--json", o.json.path);
  outs.AddOutput("--plot", o.plot);
  outs.Check();
  const std::vector<Source> sources = ListSources(o);
  std::optional<RobotParams> params;
  if (!o.params_file.empty()) params = io::ReadParamsJson(o.params_file, sources.front().recorded);

  // Stream each file run by run: only the run in hand is in memory (and the
  // first few, for --plot).
  std::vector<RunEvaluation> base_runs, param_runs;
  std::vector<PlotRun> plot_runs;
  std::set<std::string> manifests_with_trajectories;
  for (const auto& src : sources) {
    io::OpenedRunFile file = io::OpenRunFile(src.path);
    auto* reader = std::get_if<io::TrajectoryReader>(&file);
    if (reader == nullptr) {
      if (!src.manifest.empty()) continue;
      throw InputError(src.path, "evaluate needs a trajectory CSV (ticks or wheel travel with ground truth)");
    }
    manifests_with_trajectories.insert(src.manifest);
    TrajectoryRun run;
    while (reader->NextRun(run)) {
      base_runs.push_back(EvaluateRun(run, src.path, src.label, src.recorded, src.recorded, integ));
      if (params) param_runs.push_back(EvaluateRun(run, src.path, src.label, *params, src.recorded, integ));
      if (!o.plot.empty() && plot_runs.size() < kPlotRuns) plot_runs.push_back({&src, run});
    }
  }
  for (const auto& src : sources) {
    if (!src.manifest.empty() && manifests_with_trajectories.count(src.manifest) == 0) {
      throw InputError(src.manifest, "no experiment of the manifest has trajectory data to evaluate");
    }
  }
  const EvaluationSummary base = Summarise(std::move(base_runs));
  const EvaluationSummary& main = params ? Summarise(std::move(param_runs)) : base;
  if (o.json.PrintText()) {
    if (params) {
      PrintSummary("Recorded parameters", base);
      fmt::print("\n");
      PrintSummary(fmt::format("Parameters from {}", o.params_file).c_str(), main);
    } else {
      PrintSummary("Recorded parameters", base);
    }
  }
  nlohmann::json j = {{"integrator", o.integrator},
                      {"parameters", JsonParams(params ? *params : sources.front().recorded)},
                      {"runs", JsonEvaluationRuns(main)},
                      {"summary", JsonEvaluationSummary(main)}};
  if (params) {
    j["recorded"] = {{"parameters", JsonParams(sources.front().recorded)},
                     {"runs", JsonEvaluationRuns(base)},
                     {"summary", JsonEvaluationSummary(base)}};
  }
  if (!o.plot.empty()) outs.Write(o.plot, PlotSvg(plot_runs, params, integ));
  o.json.Emit(j);
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
  app->add_option("--plot", opts->plot, "Write an SVG overlaying ground truth and odometry (before/after)");
  return {app, [opts] { return RunEvaluate(*opts); }};
}

}  // namespace umbmark::cli
