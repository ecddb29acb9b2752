// Plots of a calibration (see calibrate_plot.hpp).
#include "api/calibrate_plot.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "evaluation/run_track.hpp"
#include "report/svg_plot.hpp"

namespace umbmark::api {

namespace {
// cw and ccw differ by marker and fill as well as colour (greyscale-safe).
const io::SvgStyle kCw{"#1f5fa8", "circle", "", 1.5, true};
const io::SvgStyle kCcw{"#c0392b", "triangle", "", 1.5, false};
const io::SvgStyle kDropped{"#777", "cross", "", 1.5, true};
constexpr double kScale95 = 2.4477;  // sqrt(chi^2_2(0.95)): 2-D 95% ellipse

struct Cluster {
  std::vector<io::SvgPoint> pts;  // mm
  double cx = 0, cy = 0, sxx = 0, sxy = 0, syy = 0;  // mean and covariance of the mean (SEM^2), mm^2
};

Cluster ClusterOfRuns(const std::vector<ReturnError>& errors, const std::vector<RunFlag>& flags, const char* dir) {
  Cluster c;
  for (std::size_t i = 0; i < errors.size(); ++i)
    if (errors[i].direction == dir && flags[i].used()) c.pts.push_back({errors[i].ex_m * 1e3, errors[i].ey_m * 1e3});
  const double n = static_cast<double>(c.pts.size());
  if (n < 1) return c;
  for (const auto& p : c.pts) { c.cx += p.x / n; c.cy += p.y / n; }
  if (n < 2) return c;
  for (const auto& p : c.pts) {
    c.sxx += (p.x - c.cx) * (p.x - c.cx) / (n - 1) / n;
    c.sxy += (p.x - c.cx) * (p.y - c.cy) / (n - 1) / n;
    c.syy += (p.y - c.cy) * (p.y - c.cy) / (n - 1) / n;
  }
  return c;
}

struct ErrorPanelData {
  std::string title;
  Cluster cw, ccw;
  std::vector<io::SvgPoint> dropped;
  double e_max_mm = 0;
};

ErrorPanelData PanelData(const std::string& title, const std::vector<ReturnError>& errors,
                         const std::vector<RunFlag>& flags) {
  ErrorPanelData d;
  d.title = title;
  d.cw = ClusterOfRuns(errors, flags, "cw");
  d.ccw = ClusterOfRuns(errors, flags, "ccw");
  for (std::size_t i = 0; i < errors.size(); ++i)
    if (!flags[i].used()) d.dropped.push_back({errors[i].ex_m * 1e3, errors[i].ey_m * 1e3});
  d.e_max_mm = std::max(std::hypot(d.cw.cx, d.cw.cy), std::hypot(d.ccw.cx, d.ccw.cy));  // eq. 3.4
  return d;
}

io::SvgPanel ErrorPanel(double left, double top, const ErrorPanelData& d, double half_extent_mm) {
  io::SvgPanel p(left, top, 400, 400, d.title);
  p.SetExtent(-half_extent_mm, half_extent_mm, -half_extent_mm, half_extent_mm, true);
  p.Axes("return error e_x [mm]", "return error e_y [mm]");
  const io::SvgStyle emax{"#444", "", "6,4", 1.3, false};
  p.Circle({0, 0}, d.e_max_mm, emax);
  p.Points(d.cw.pts, kCw);
  p.Points(d.ccw.pts, kCcw);
  if (!d.dropped.empty()) p.Points(d.dropped, kDropped, 4.5);
  const io::SvgStyle cg_cw{kCw.color, "plus", "", 1.5, true}, cg_ccw{kCcw.color, "plus", "", 1.5, true};
  const io::SvgStyle sem_cw{kCw.color, "", "", 1.2, false}, sem_ccw{kCcw.color, "", "2,2", 1.2, false};
  p.CovarianceEllipse({d.cw.cx, d.cw.cy}, d.cw.sxx, d.cw.sxy, d.cw.syy, kScale95, sem_cw);
  p.CovarianceEllipse({d.ccw.cx, d.ccw.cy}, d.ccw.sxx, d.ccw.sxy, d.ccw.syy, kScale95, sem_ccw);
  p.Points({{d.cw.cx, d.cw.cy}}, cg_cw, 6);
  p.Points({{d.ccw.cx, d.ccw.cy}}, cg_ccw, 6);
  std::vector<std::pair<io::SvgStyle, std::string>> legend = {
      {kCw, fmt::format("cw runs ({}); + centre of gravity, solid ellipse: its 95% SEM", d.cw.pts.size())},
      {kCcw, fmt::format("ccw runs ({}); + centre of gravity, dotted ellipse: its 95% SEM", d.ccw.pts.size())},
      {emax, fmt::format("E_max,syst = {:.2f} mm (larger c.g. distance)", d.e_max_mm)}};
  if (!d.dropped.empty()) legend.push_back({kDropped, fmt::format("excluded or rejected runs ({})", d.dropped.size())});
  p.Legend(legend);
  return p;
}

double HalfExtent(const std::vector<const ErrorPanelData*>& panels) {
  double m = 1e-3;
  for (const auto* d : panels) {
    m = std::max(m, d->e_max_mm);
    for (const auto* pts : {&d->cw.pts, &d->ccw.pts, &d->dropped})
      for (const auto& q : *pts) m = std::max({m, std::abs(q.x), std::abs(q.y)});
  }
  return 1.1 * m;
}
// Paths of every run (trajectory input): ground truth vs odometry before
// and after, small multiples in file order; the kWorstMarked runs with
// the largest final error after correction are marked. Beyond
// kMaxPathPanels runs, those with the largest errors are drawn (said so).
// Returns the new bottom; widens `width` to the grid. One function: the
// ranking by final error decides both which runs are drawn and which are
// marked, so it stays beside the drawing.
double PathPanels(const CalibrateInput& input, Integrator integrator, const RobotParams& corrected, const std::string& which,
                  double bottom, double& width, std::vector<std::string>& parts) {
  const io::SvgStyle gt{"#111", "", "", 2.0, false}, od0{"#c0392b", "", "5,3", 1.3, false},
      od1{"#1f7a3a", "", "1.5,2.5", 1.7, false};
  constexpr std::size_t kMaxPathPanels = 48, kWorstMarked = 3, kColumns = 6;
  const auto& all_runs = input.trajectories->runs;
  struct Tracked {
    std::size_t index;
    RunTrack before, after;
    double final_after_mm = 0.0;
  };
  std::vector<Tracked> tracked;
  tracked.reserve(all_runs.size());
  for (std::size_t i = 0; i < all_runs.size(); ++i) {
    Tracked t{i, TrackRun(all_runs[i], input.trajectories->path, input.recorded, input.recorded, integrator),
              TrackRun(all_runs[i], input.trajectories->path, corrected, input.recorded, integrator), 0.0};
    for (std::size_t k = all_runs[i].size(); k-- > 0;)
      if (t.after.has_ground_truth[k]) {
        t.final_after_mm = 1e3 * std::hypot(t.after.ground_truth[k].x - t.after.odometry[k].x,
                                            t.after.ground_truth[k].y - t.after.odometry[k].y);
        break;
      }
    tracked.push_back(std::move(t));
  }
  std::vector<std::size_t> by_error(tracked.size());
  for (std::size_t i = 0; i < by_error.size(); ++i) by_error[i] = i;
  std::stable_sort(by_error.begin(), by_error.end(),
                   [&](std::size_t x, std::size_t y) { return tracked[x].final_after_mm > tracked[y].final_after_mm; });
  std::vector<int> worst_rank(tracked.size(), 0);
  for (std::size_t r = 0; r < std::min(kWorstMarked, by_error.size()); ++r) worst_rank[by_error[r]] = static_cast<int>(r + 1);
  std::vector<std::size_t> shown = by_error;
  if (shown.size() > kMaxPathPanels) shown.resize(kMaxPathPanels);
  std::sort(shown.begin(), shown.end());  // file order
  const double size = 150, gap_x = 62, gap_y = 84, top0 = bottom + 56;
  parts.push_back(fmt::format(
      R"svg(<text class="section-title" x="80" y="{:.0f}" font-size="13" font-weight="bold">{}</text>)svg", bottom + 24,
      io::XmlEscape(shown.size() < tracked.size()
                        ? fmt::format("Paths: the {} of {} runs with the largest final error after correction "
                                      "(file order); title: run, direction, final position error after correction",
                                      shown.size(), tracked.size())
                        : fmt::format("Paths of all {} runs (file order); title: run, direction, final position "
                                      "error after correction; the {} largest marked",
                                      tracked.size(), std::min(kWorstMarked, tracked.size())))));
  double row_bottom = top0;
  for (std::size_t n = 0; n < shown.size(); ++n) {
    const Tracked& t = tracked[shown[n]];
    const auto& run = all_runs[t.index];
    const double left = 80 + static_cast<double>(n % kColumns) * (size + gap_x);
    const double top = top0 + static_cast<double>(n / kColumns) * (size + gap_y);
    const int rank = worst_rank[shown[n]];
    io::SvgPanel p(left, top, size, size,
                   rank > 0 ? fmt::format("WORST {}: {} {}, {:.1f} mm", rank, run.run, run.direction, t.final_after_mm)
                            : fmt::format("{} {}, {:.1f} mm", run.run, run.direction, t.final_after_mm));
    std::vector<io::SvgPoint> g, o0, o1, all;
    for (std::size_t k = 0; k < run.size(); ++k) {
      if (t.before.has_ground_truth[k]) g.push_back({t.before.ground_truth[k].x, t.before.ground_truth[k].y});
      o0.push_back({t.before.odometry[k].x, t.before.odometry[k].y});
      o1.push_back({t.after.odometry[k].x, t.after.odometry[k].y});
    }
    all = g;
    all.insert(all.end(), o0.begin(), o0.end());
    p.FitExtent(all, true, true);
    p.Axes("x [m]", "y [m]");
    p.Polyline(g, gt);
    p.Polyline(o0, od0);
    p.Polyline(o1, od1);
    row_bottom = std::max(row_bottom, p.Bottom());
    std::string panel = p.Render();
    if (rank > 0)  // a heavy frame: the marked runs stand out in greyscale too
      panel += fmt::format(R"svg(<rect class="worst-frame" x="{:.1f}" y="{:.1f}" width="{:.1f}" height="{:.1f}" fill="none" stroke="#b02020" stroke-width="3"/>)svg",
                           left - 2, top - 2, size + 4, size + 4);
    parts.push_back(panel);
  }
  // One legend for all path panels.
  io::SvgPanel legend(80, row_bottom - 36, 0, 0, "");
  legend.Legend({{gt, "ground truth"},
                 {od0, "odometry, recorded parameters"},
                 {od1, fmt::format("odometry, {} parameters", which)}});
  parts.push_back(legend.Render());
  bottom = legend.Bottom() + 10;
  width = std::max(width, 80 + static_cast<double>(kColumns) * (size + gap_x));
  bottom += 14;
  width = std::max(width, 80 + static_cast<double>(kColumns) * (size + gap_x));
  return legend.Bottom() + 24;
}

}  // namespace

std::string CalibrationPlotSvg(const CalibrateInput& input, const CalibrateJobResult& result, Integrator integrator,
                               const RobotParams& corrected, const std::string& which) {
  const auto& s = result.umbmark;
  std::vector<std::string> parts;
  const ErrorPanelData before =
      PanelData(fmt::format("Before: recorded parameters (L = {} m)", input.side_m), input.errors, s.runs);
  std::optional<ErrorPanelData> after;
  if (input.trajectories) {
    const auto errors = ReturnErrorsFromTrajectories(*input.trajectories, corrected, input.recorded, integrator);
    after = PanelData(fmt::format("After correction: {} parameters (same runs)", which), errors, s.runs);
  }
  // One common scale, so the improvement shows as it is.
  const double half = after ? HalfExtent({&before, &*after}) : HalfExtent({&before});
  io::SvgPanel pb = ErrorPanel(80, 40, before, half);
  parts.push_back(pb.Render());
  double bottom = pb.Bottom(), width = 540;
  if (after) {
    io::SvgPanel pa = ErrorPanel(600, 40, *after, half);
    parts.push_back(pa.Render());
    bottom = std::max(bottom, pa.Bottom());
    width = 1060;
  }
  if (input.trajectories) bottom = PathPanels(input, integrator, corrected, which, bottom, width, parts);
  return io::SvgDocument(width, bottom + 10, parts);
}

}  // namespace umbmark::api
