// The figure and HTML page of `evaluate --plot/--report` (see
// evaluate_report.hpp).
#include "api/evaluate_report.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/angles.hpp"
#include "evaluation/run_track.hpp"
#include "report/html_report.hpp"
#include "report/svg_plot.hpp"
#include "report/xml_escape.hpp"

namespace umbmark::api {

namespace {

// The paths of the worst runs (`worst`: indices into `runs`, worst first;
// `final_mm`: their final position errors), each on its own scale, with one
// key below. Returns the bottom.
double WorstPathPanels(const std::vector<EvaluatePlotRun>& runs, const std::vector<std::size_t>& worst,
                       const std::vector<double>& final_mm, const std::optional<RobotParams>& params, Integrator integ,
                       double bottom, std::vector<std::string>& parts) {
  const io::SvgStyle rec_bold{"#c0392b", "", "5,3", 1.6, false}, par_bold{"#1f7a3a", "", "", 2.0, false};
  const io::SvgStyle gt{"#111", "", "", 2.2, false};
  const double size = 250;
  double row_bottom = bottom;
  for (std::size_t r = 0; r < worst.size(); ++r) {
    const auto& [path, recorded, run] = runs[worst[r]];
    const double left = 80 + static_cast<double>(r % 4) * (size + 60), top = bottom + static_cast<double>(r / 4) * (size + 90);
    io::SvgPanel p(left, top, size, size,
                   fmt::format("{}: run {} ({}), {:.1f} mm", r + 1, run.run, run.direction, final_mm[r]));
    const RunTrack b = TrackRun(run, path, recorded, recorded, integ);
    std::vector<io::SvgPoint> g, o0, o1, all;
    for (std::size_t i = 0; i < run.size(); ++i) {
      if (b.has_ground_truth[i]) g.push_back({b.ground_truth[i].x, b.ground_truth[i].y});
      o0.push_back({b.odometry[i].x, b.odometry[i].y});
    }
    if (params) {
      const RunTrack a = TrackRun(run, path, *params, recorded, integ);
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

/// Runs with the largest final error: highlighted and drawn as paths.
constexpr std::size_t kWorstRuns = 8;

// Position and heading error along the travelled distance for every run
// (thin lines; recorded parameters vs --params, one common scale), the
// kWorstRuns with the largest final position error (with --params when
// given) drawn bold and numbered; then the paths of those runs, worst
// first: what `evaluate --plot` and its report show. `total_runs`: all runs
// evaluated (more than `runs` when the plot kept only the first kEvaluatePlotRuns).
std::string PlotSvg(const std::vector<EvaluatePlotRun>& runs, const std::optional<RobotParams>& params, Integrator integ,
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
  for (const auto& [path, recorded, run] : runs) {
    before.push_back(curve(run, path, recorded, recorded));
    if (params) after.push_back(curve(run, path, *params, recorded));
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

}  // namespace

std::string EvaluatePlotSvg(const EvaluateResult& result) {
  return PlotSvg(result.plot_runs, result.params, IntegratorFromString(result.integrator).value_or(Integrator::kArc),
                 result.Base().runs.size());
}

std::string EvaluateReportHtml(const EvaluateResult& result, const std::vector<std::string>& inputs,
                               const std::string& params_file, const std::string& svg) {
  const EvaluationSummary& base = result.Base();
  const std::optional<EvaluationSummary> with_params =
      result.recorded ? std::optional<EvaluationSummary>(result.summary) : std::nullopt;
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
                              kEvaluatePlotRuns, kWorstRuns));
  return rep.Render();
}

}  // namespace umbmark::api
