// Plots of a calibration (see calibrate_plot.hpp).
#include "calibrate_plot.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "evaluation/run_track.hpp"
#include "io/svg_plot.hpp"

namespace umbmark::cli {

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
  // Paths of each run (trajectory input): ground truth vs odometry before/after.
  if (input.trajectories) {
    const io::SvgStyle gt{"#111", "", "", 2.2, false}, od0{"#c0392b", "", "5,3", 1.4, false},
        od1{"#1f7a3a", "", "1.5,2.5", 1.8, false};
    const double size = 220, top0 = bottom + 40;
    const std::size_t runs = std::min<std::size_t>(input.trajectories->runs.size(), 8);
    double row_bottom = top0;
    for (std::size_t i = 0; i < runs; ++i) {
      const auto& run = input.trajectories->runs[i];
      const double left = 80 + static_cast<double>(i % 4) * (size + 75);
      const double top = top0 + static_cast<double>(i / 4) * (size + 90);
      io::SvgPanel p(left, top, size, size, fmt::format("run {} ({})", run.run, run.direction));
      const RunTrack b = TrackRun(run, input.trajectories->path, input.recorded, input.recorded, integrator);
      const RunTrack a = TrackRun(run, input.trajectories->path, corrected, input.recorded, integrator);
      std::vector<io::SvgPoint> g, o0, o1, all;
      for (std::size_t k = 0; k < run.size(); ++k) {
        if (b.has_ground_truth[k]) g.push_back({b.ground_truth[k].x, b.ground_truth[k].y});
        o0.push_back({b.odometry[k].x, b.odometry[k].y});
        o1.push_back({a.odometry[k].x, a.odometry[k].y});
      }
      all = g;
      all.insert(all.end(), o0.begin(), o0.end());
      p.FitExtent(all, true, true);
      p.Axes("x [m]", "y [m]");
      p.Polyline(g, gt);
      p.Polyline(o0, od0);
      p.Polyline(o1, od1);
      row_bottom = std::max(row_bottom, p.Bottom());
      parts.push_back(p.Render());
    }
    if (runs < input.trajectories->runs.size()) {
      row_bottom += 6;
    }
    // One legend for all path panels.
    io::SvgPanel legend(80, row_bottom - 36, 0, 0, "");
    legend.Legend({{gt, "ground truth"},
                   {od0, "odometry, recorded parameters"},
                   {od1, fmt::format("odometry, {} parameters", which)}});
    parts.push_back(legend.Render());
    bottom = legend.Bottom() + 10;
    width = std::max(width, 80 + 4 * (size + 75));
    if (runs < input.trajectories->runs.size())
      parts.push_back(fmt::format(R"svg(<text x="80" y="{:.0f}" font-size="11">first {} of {} runs shown</text>)svg",
                                  bottom + 6, runs, input.trajectories->runs.size()));
    bottom += 14;
  }
  return io::SvgDocument(width, bottom + 10, parts);
}

}  // namespace umbmark::cli
