// `umbmark evaluate DATA... --robot R.toml [--params CAL.json]`: errors of
// odometry against ground truth along trajectories (any path shape) for the
// recorded parameters or a calibration, per run and over all runs.
#include <cmath>
#include <algorithm>
#include <exception>
#include <filesystem>
#include <iterator>
#include <memory>
#include <set>
#include <optional>
#include <thread>
#include <variant>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "common.hpp"
#include "core/angles.hpp"
#include "core/errors.hpp"
#include "evaluation/data_warnings.hpp"
#include "evaluation/run_track.hpp"
#include "output/atomic_write.hpp"
#include "report/html_report.hpp"
#include "formats/data_file.hpp"
#include "formats/params_json.hpp"
#include "formats/run_prefetch.hpp"
#include "formats/manifest.hpp"
#include "report/svg_plot.hpp"

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

// The paths of the worst runs (`worst`: indices into `runs`, worst first;
// `final_mm`: their final position errors), each on its own scale, with one
// key below. Returns the bottom.
double WorstPathPanels(const std::vector<PlotRun>& runs, const std::vector<std::size_t>& worst,
                       const std::vector<double>& final_mm, const std::optional<RobotParams>& params, Integrator integ,
                       double bottom, std::vector<std::string>& parts) {
  const io::SvgStyle rec_bold{"#c0392b", "", "5,3", 1.6, false}, par_bold{"#1f7a3a", "", "", 2.0, false};
  const io::SvgStyle gt{"#111", "", "", 2.2, false};
  const double size = 250;
  double row_bottom = bottom;
  for (std::size_t r = 0; r < worst.size(); ++r) {
    const auto& [source, run] = runs[worst[r]];
    const Source& src = *source;
    const double left = 80 + static_cast<double>(r % 4) * (size + 60), top = bottom + static_cast<double>(r / 4) * (size + 90);
    io::SvgPanel p(left, top, size, size,
                   fmt::format("{}: run {} ({}), {:.1f} mm", r + 1, run.run, run.direction, final_mm[r]));
    const RunTrack b = TrackRun(run, src.path, src.recorded, src.recorded, integ);
    std::vector<io::SvgPoint> g, o0, o1, all;
    for (std::size_t i = 0; i < run.size(); ++i) {
      if (b.has_ground_truth[i]) g.push_back({b.ground_truth[i].x, b.ground_truth[i].y});
      o0.push_back({b.odometry[i].x, b.odometry[i].y});
    }
    if (params) {
      const RunTrack a = TrackRun(run, src.path, *params, src.recorded, integ);
      for (const auto& q : a.odometry) o1.push_back({q.x, q.y});
    }
    all = g;
    all.insert(all.end(), o0.begin(), o0.end());
    p.FitExtent(all, true, true);
    p.Axes("x [m]", "y [m]");
    p.Polyline(g, gt);
    p.Polyline(o0, rec_bold);
    if (params) p.Polyline(o1, par_bold);
    row_bottom = std::max(row_bottom, p.Bottom());
    parts.push_back(p.Render());
  }
  io::SvgPanel key(80, row_bottom - 36, 0, 0, "");
  std::vector<std::pair<io::SvgStyle, std::string>> key_entries = {{gt, "ground truth"},
                                                                   {rec_bold, "odometry with the recorded parameters"}};
  if (params) key_entries.push_back({par_bold, "odometry with the --params parameters"});
  key.Legend(key_entries);
  parts.push_back(key.Render());
  return key.Bottom();
}

/// Runs kept for the --plot figure: every run up to this many (the plot
/// says when there were more).
constexpr std::size_t kPlotRuns = 200;
/// Runs with the largest final error: highlighted and drawn as paths.
constexpr std::size_t kWorstRuns = 8;

// Position and heading error along the travelled distance for every run
// (thin lines; recorded parameters vs --params, one common scale), the
// kWorstRuns with the largest final position error (with --params when
// given) drawn bold and numbered; then the paths of those runs, worst
// first: what `evaluate --plot` and its report show. `total_runs`: all runs
// evaluated (more than `runs` when the plot kept only the first kPlotRuns).
std::string PlotSvg(const std::vector<PlotRun>& runs, const std::optional<RobotParams>& params, Integrator integ,
                    std::size_t total_runs) {
  const io::SvgStyle rec{"#e3a59c", "", "5,3", 0.8, false}, par{"#9cc7a8", "", "", 0.9, false};
  const io::SvgStyle rec_bold{"#c0392b", "", "5,3", 1.6, false}, par_bold{"#1f7a3a", "", "", 2.0, false};
  struct Curve {
    std::vector<io::SvgPoint> pos, head;  // (travel m, error mm) and (travel m, error deg)
  };
  auto curve = [&](const TrajectoryRun& run, const std::string& path, const RobotParams& p, const RobotParams& recorded) {
    const RunTrack t = TrackRun(run, path, p, recorded, integ);
    Curve c;
    double travel = 0.0;
    for (std::size_t i = 0; i < run.size(); ++i) {
      if (i > 0) travel += std::hypot(t.odometry[i].x - t.odometry[i - 1].x, t.odometry[i].y - t.odometry[i - 1].y);
      if (!t.has_ground_truth[i]) continue;
      c.pos.push_back({travel, 1e3 * std::hypot(t.ground_truth[i].x - t.odometry[i].x, t.ground_truth[i].y - t.odometry[i].y)});
      c.head.push_back({travel, Rad2Deg(std::abs(WrapAngle(t.ground_truth[i].theta - t.odometry[i].theta)))});
    }
    return c;
  };
  std::vector<Curve> before, after;
  std::vector<io::SvgPoint> all_pos, all_head;
  for (const auto& [source, run] : runs) {
    const Source& src = *source;
    before.push_back(curve(run, src.path, src.recorded, src.recorded));
    if (params) after.push_back(curve(run, src.path, *params, src.recorded));
  }
  for (const auto* set : {&before, &after})
    for (const auto& c : *set) {
      all_pos.insert(all_pos.end(), c.pos.begin(), c.pos.end());
      all_head.insert(all_head.end(), c.head.begin(), c.head.end());
    }
  // The worst runs by final position error (with --params when given).
  const std::vector<Curve>& ranked_set = params ? after : before;
  std::vector<std::size_t> worst(ranked_set.size());
  for (std::size_t i = 0; i < worst.size(); ++i) worst[i] = i;
  auto final_mm = [&](std::size_t i) { return ranked_set[i].pos.empty() ? 0.0 : ranked_set[i].pos.back().y; };
  std::stable_sort(worst.begin(), worst.end(), [&](std::size_t x, std::size_t y) { return final_mm(x) > final_mm(y); });
  if (worst.size() > kWorstRuns) worst.resize(kWorstRuns);
  const std::string which = params ? "--params" : "recorded";
  std::vector<std::string> parts;
  io::SvgPanel pp(80, 40, 520, 340,
                  runs.size() < total_runs
                      ? fmt::format("Position error along the path (first {} of {} runs)", runs.size(), total_runs)
                      : fmt::format("Position error along the path (all {} runs)", runs.size()));
  io::SvgPanel ph(700, 40, 520, 340, "Heading error along the path");
  pp.FitExtent(all_pos, false, true);
  ph.FitExtent(all_head, false, true);
  pp.Axes("distance travelled [m]", "position error [mm]");
  ph.Axes("distance travelled [m]", "heading error [deg]");
  for (const auto& c : before) { pp.Polyline(c.pos, rec); ph.Polyline(c.head, rec); }
  for (const auto& c : after) { pp.Polyline(c.pos, par); ph.Polyline(c.head, par); }
  // The worst on top, bold, numbered at their end.
  for (std::size_t r = 0; r < worst.size(); ++r) {
    const std::size_t i = worst[r];
    pp.Polyline(before[i].pos, rec_bold);
    ph.Polyline(before[i].head, rec_bold);
    if (params) { pp.Polyline(after[i].pos, par_bold); ph.Polyline(after[i].head, par_bold); }
    if (!ranked_set[i].pos.empty()) pp.Text(ranked_set[i].pos.back(), fmt::format(" {}", r + 1), "#111", 11);
  }
  std::vector<std::pair<io::SvgStyle, std::string>> legend = {{rec, "odometry with the recorded parameters (one line per run)"}};
  if (params) legend.push_back({par, "odometry with the --params parameters"});
  legend.push_back({params ? par_bold : rec_bold,
                    fmt::format("bold, numbered: the {} runs with the largest final error ({})", worst.size(), which)});
  pp.Legend(legend);
  parts.push_back(pp.Render());
  parts.push_back(ph.Render());
  double bottom = std::max(pp.Bottom(), ph.Bottom()) + 30;
  parts.push_back(fmt::format(
      R"svg(<text class="section-title" x="80" y="{:.0f}" font-size="13" font-weight="bold">{}</text>)svg", bottom,
      io::XmlEscape(fmt::format("Paths of the {} runs with the largest final position error ({}), worst first", worst.size(),
                                which))));
  bottom += 30;
  std::vector<double> worst_mm;
  for (std::size_t i : worst) worst_mm.push_back(final_mm(i));
  return io::SvgDocument(1260, WorstPathPanels(runs, worst, worst_mm, params, integ, bottom, parts) + 10, parts);
}

std::string EvaluateReportHtml(const std::vector<std::string>& inputs, const EvaluationSummary& base,
                               const std::optional<EvaluationSummary>& with_params, const std::string& params_file,
                               const std::string& svg) {
  std::string subject;
  for (const auto& i : inputs) subject += (subject.empty() ? "" : ", ") + i;
  io::HtmlReport rep("umbmark evaluate", subject);
  const EvaluationSummary& m = with_params ? *with_params : base;
  if (with_params) {
    const double b = base.mean_final_position_error_m * 1e3, a = with_params->mean_final_position_error_m * 1e3;
    rep.Headline(fmt::format("Mean final position error {:.2f} mm with the recorded parameters, {:.2f} mm with {} ({}).",
                             b, a, params_file, a < b ? fmt::format("{:.1f}x smaller", b / std::max(a, 1e-9)) : "no better"),
                 a < b ? io::HtmlReport::Level::kGood : io::HtmlReport::Level::kWarn);
  } else {
    rep.Headline(fmt::format("Over {} runs the odometry ends {:.2f} mm (mean) and at worst {:.2f} mm from the ground truth; "
                             "heading at worst {:.3f} deg.",
                             m.runs.size(), m.mean_final_position_error_m * 1e3, m.max_final_position_error_m * 1e3,
                             Rad2Deg(m.max_final_heading_error_rad)),
                 io::HtmlReport::Level::kInfo);
  }
  rep.NextSteps(with_params ? std::vector<std::string>{"If the calibrated parameters reduce the error, load them into the robot's odometry.",
                                                       "If one run stands out below, check that run (slip, a bump, lost tracking)."}
                            : std::vector<std::string>{"Calibrate (`umbmark calibrate` on squares) and evaluate again with --params CAL.json."});
  auto row = [](const std::string& name, const EvaluationSummary& e) {
    return std::vector<std::string>{name, fmt::format("{:.2f}", e.mean_final_position_error_m * 1e3),
                                    fmt::format("{:.2f}", e.max_final_position_error_m * 1e3),
                                    fmt::format("{:.2f}", e.max_max_position_error_m * 1e3),
                                    fmt::format("{:.3f}", Rad2Deg(e.mean_final_heading_error_rad)),
                                    fmt::format("{:.3f}", Rad2Deg(e.max_max_heading_error_rad))};
  };
  rep.Heading("Summary over runs");
  std::vector<std::vector<std::string>> rows = {row("recorded parameters", base)};
  if (with_params) rows.push_back(row(params_file, *with_params));
  rep.Table({"odometry with", "final position error, mean [mm]", "final, max [mm]", "max along the path [mm]",
             "final heading error, mean [deg]", "max heading error [deg]"},
            rows);
  rep.Heading("Per run");
  rows.clear();
  for (const auto& r : m.runs)
    rows.push_back({fmt::format("{} run {} ({})", r.experiment, r.run, r.direction),
                    fmt::format("{:.2f}", r.final_position_error_m * 1e3), fmt::format("{:.2f}", r.max_position_error_m * 1e3),
                    fmt::format("{:.3f}", Rad2Deg(r.final_heading_error_rad)),
                    fmt::format("{:.3f}", Rad2Deg(r.max_heading_error_rad))});
  rep.Table({"run", "final position error [mm]", "max position error [mm]", "final heading error [deg]",
             "max heading error [deg]"},
            rows);
  rep.Heading("Plots");
  rep.Figure(svg, fmt::format("Error along the travelled distance for every run (up to {}; the {} largest final errors "
                              "bold and numbered), then the paths of those runs, worst first.",
                              kPlotRuns, kWorstRuns));
  return rep.Render();
}

/// What evaluating one file (or a part of one) gives.
struct FileResult {
  std::vector<RunEvaluation> base, param;  ///< recorded parameters; --params
  TrajectoryDataCheck check;
  explicit FileResult(const RobotParams& recorded) : check(recorded) {}
  void Add(const TrajectoryRun& run, const Source& src, const std::optional<RobotParams>& params, Integrator integ) {
    check.Add(run);
    base.push_back(EvaluateRun(run, src.path, src.label, src.recorded, src.recorded, integ));
    if (params) param.push_back(EvaluateRun(run, src.path, src.label, *params, src.recorded, integ));
  }
};

/// Files at least this large are evaluated in two parts at once.
constexpr std::uint64_t kPartsFromBytes = std::uint64_t{32} << 20;

// A large file cut in two at a run boundary near its middle, each part read
// and evaluated on its own thread, the results joined in file order: the
// whole process takes about half the time on two cores. Any fault in either
// part, or a run id in both parts (a run split in two blocks, an error the
// sequential read names), gives nullopt: the caller then reads the file in
// one pass from `whole` (still at its first row), so every message is the
// sequential read's.
std::optional<FileResult> EvaluateInParts(const io::TrajectoryReader& whole, const Source& src,
                                          const std::optional<RobotParams>& params, Integrator integ) {
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(src.path, ec);
  if (ec || size < kPartsFromBytes || std::thread::hardware_concurrency() < 2) return std::nullopt;
  const auto cut = io::FindRunBoundary(src.path, size / 2, whole.run_column());
  if (!cut || *cut <= whole.offset()) return std::nullopt;
  FileResult first(src.recorded), second(src.recorded);
  std::vector<std::string> first_ids, second_ids;
  std::exception_ptr first_error, second_error;
  const auto evaluate = [&](std::uint64_t begin, std::uint64_t end, std::size_t line, FileResult& out,
                            std::vector<std::string>& ids, std::exception_ptr& error) {
    try {
      io::TrajectoryReader part(whole, begin, end, line == 0 ? io::LineAtOffset(src.path, begin) : line);
      TrajectoryRun run;
      while (part.NextRun(run)) out.Add(run, src, params, integ);
      ids = part.RunIds();
    } catch (...) {
      error = std::current_exception();
    }
  };
  std::thread later([&] { evaluate(*cut, size, 0, second, second_ids, second_error); });
  evaluate(whole.offset(), *cut, whole.next_line(), first, first_ids, first_error);
  later.join();
  if (first_error || second_error) return std::nullopt;
  std::sort(first_ids.begin(), first_ids.end());
  for (const auto& id : second_ids)
    if (std::binary_search(first_ids.begin(), first_ids.end(), id)) return std::nullopt;
  std::move(second.base.begin(), second.base.end(), std::back_inserter(first.base));
  std::move(second.param.begin(), second.param.end(), std::back_inserter(first.param));
  first.check.Merge(second.check);
  return first;
}

// Longer than 80 lines on purpose: the command's steps in order (read the
// parameters, stream every file run by run, summarise, print, then the JSON,
// plots and report), all sharing the two summaries; each step is a call or
// a few lines.
int RunEvaluate(const EvaluateOptions& o) {
  const Integrator integ = *IntegratorFromString(o.integrator);
  io::OutputSet& outs = CommandOutputs();
  RegisterInputs(o.inputs, &o.robot);
  outs.AddInput(o.params_file);
  outs.AddOutput("--json", o.json.path);
  outs.AddOutput("--plot", o.plot);
  outs.AddOutput("--report", o.report);
  outs.Check();
  const std::vector<Source> sources = ListSources(o);
  std::optional<RobotParams> params;
  if (!o.params_file.empty()) params = io::ReadParamsJson(o.params_file, sources.front().recorded);

  // Stream each file run by run: only the run in hand is in memory (and the
  // first few, for --plot).
  std::vector<RunEvaluation> base_runs, param_runs;
  std::vector<PlotRun> plot_runs;
  std::set<std::string> manifests_with_trajectories;
  std::vector<std::string> warnings;  // degenerate data (evaluation/data_warnings.hpp)
  for (const auto& src : sources) {
    io::OpenedRunFile file = io::OpenRunFile(src.path);
    auto* reader = std::get_if<io::TrajectoryReader>(&file);
    if (reader == nullptr) {
      if (!src.manifest.empty()) continue;
      throw InputError(src.path, "evaluate needs a trajectory CSV (ticks or wheel travel with ground truth)");
    }
    manifests_with_trajectories.insert(src.manifest);
    const bool plots = !o.plot.empty() || !o.report.empty();
    std::optional<FileResult> r;
    if (!plots) r = EvaluateInParts(*reader, src, params, integ);
    if (!r) {
      r.emplace(src.recorded);
      // The next run is read on a second thread while this one is evaluated.
      io::RunPrefetcher prefetch(*reader);
      TrajectoryRun run;
      while (prefetch.NextRun(run)) {
        r->Add(run, src, params, integ);
        if (plots && plot_runs.size() < kPlotRuns) plot_runs.push_back({&src, run});
      }
    }
    std::move(r->base.begin(), r->base.end(), std::back_inserter(base_runs));
    std::move(r->param.begin(), r->param.end(), std::back_inserter(param_runs));
    for (auto& w : r->check.Warnings(src.path)) warnings.push_back(std::move(w));
  }
  for (const auto& src : sources) {
    if (!src.manifest.empty() && manifests_with_trajectories.count(src.manifest) == 0) {
      throw InputError(src.manifest, "no experiment of the manifest has trajectory data to evaluate");
    }
  }
  const EvaluationSummary base = Summarise(std::move(base_runs));
  std::optional<EvaluationSummary> with_params;
  if (params) with_params = Summarise(std::move(param_runs));
  const EvaluationSummary& main = with_params ? *with_params : base;
  if (o.json.PrintText()) {
    if (params) {
      PrintSummary("Recorded parameters", base);
      fmt::print("\n");
      PrintSummary(fmt::format("Parameters from {}", o.params_file).c_str(), main);
    } else {
      PrintSummary("Recorded parameters", base);
    }
    for (const auto& w : warnings) fmt::print("  WARNING: {}\n", w);
  } else {
    for (const auto& w : warnings) fmt::print(stderr, "warning: {}\n", w);
  }
  nlohmann::json j = {{"integrator", o.integrator},
                      {"parameters", JsonParams(params ? *params : sources.front().recorded)},
                      {"runs", JsonEvaluationRuns(main)},
                      {"summary", JsonEvaluationSummary(main)},
                      {"warnings", warnings}};
  if (params) {
    j["recorded"] = {{"parameters", JsonParams(sources.front().recorded)},
                     {"runs", JsonEvaluationRuns(base)},
                     {"summary", JsonEvaluationSummary(base)}};
  }
  std::vector<std::string> written;
  std::string svg;
  if (!o.plot.empty() || !o.report.empty()) svg = PlotSvg(plot_runs, params, integ, base.runs.size());
  if (!o.plot.empty()) {
    outs.Write(o.plot, svg);
    written.push_back(o.plot + " (plot)");
  }
  if (!o.report.empty()) {
    outs.Write(o.report, EvaluateReportHtml(o.inputs, base, with_params, o.params_file, svg));
    written.push_back(o.report + " (HTML report)");
  }
  o.json.EmitAndListOutputs(j, written);
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
