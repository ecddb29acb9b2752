// SVG for `calibrate --plot` (see calibrate_plot.hpp).
#include "calibrate_plot.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "io/svg_plot.hpp"

namespace umbmark::cli {

namespace {
constexpr const char* kCw = "#1f77b4";
constexpr const char* kCcw = "#d62728";

std::string Panel(double left, const std::string& title, const std::vector<ReturnError>& errors,
                  const std::vector<RunFlag>& flags, const ClusterStats& cw, const ClusterStats& ccw, double e_max) {
  io::SvgPanel p(left, 40, 420, 420, title);
  std::vector<io::SvgPoint> pts_cw, pts_ccw, pts_dropped, all;
  for (std::size_t i = 0; i < errors.size(); ++i) {
    const io::SvgPoint q{errors[i].ex_m * 1000.0, errors[i].ey_m * 1000.0};
    all.push_back(q);
    if (!flags[i].used())
      pts_dropped.push_back(q);
    else
      (errors[i].direction == "cw" ? pts_cw : pts_ccw).push_back(q);
  }
  all.push_back({e_max * 1000.0, e_max * 1000.0});
  all.push_back({-e_max * 1000.0, -e_max * 1000.0});
  p.FitExtent(all, true, true);
  p.Axes("e_x [mm]", "e_y [mm]");
  p.Circle({0, 0}, e_max * 1000.0, "#555", "5,4");
  p.Points(pts_cw, kCw);
  p.Points(pts_ccw, kCcw);
  p.Points(pts_dropped, "#999", 4.0, "cross");
  p.Points({{cw.x_cg_m * 1000.0, cw.y_cg_m * 1000.0}}, kCw, 7.0, "cross");
  p.Points({{ccw.x_cg_m * 1000.0, ccw.y_cg_m * 1000.0}}, kCcw, 7.0, "cross");
  p.Legend({{kCw, fmt::format("cw runs (c.g. r = {:.1f} mm)", cw.r_cg_m * 1000)},
            {kCcw, fmt::format("ccw runs (c.g. r = {:.1f} mm)", ccw.r_cg_m * 1000)},
            {"#555", fmt::format("E_max,syst = {:.1f} mm", e_max * 1000)},
            {"#999", "excluded / rejected"}});
  return p.Render();
}
}  // namespace

std::string CalibrationPlotSvg(const CalibrateInput& input, const CalibrateJobResult& result,
                               Integrator integrator, const RobotParams& after_params, const std::string& after_method) {
  const auto& s = result.umbmark;
  std::vector<std::string> parts;
  parts.push_back(Panel(60, fmt::format("Before: {} (L = {} m)", input.label, input.side_m), input.errors, s.runs,
                        s.cw, s.ccw, s.E_max_syst_m));
  double width = 520;
  if (result.evaluation && input.trajectories) {
    const auto after = ReturnErrorsFromTrajectories(*input.trajectories, after_params, input.recorded, integrator);
    const ClusterStats cw = ClusterOfUsed(after, s.runs, "cw"), ccw = ClusterOfUsed(after, s.runs, "ccw");
    parts.push_back(Panel(560, fmt::format("After correction: {} (same runs)", after_method), after, s.runs, cw, ccw,
                          std::max(cw.r_cg_m, ccw.r_cg_m)));
    width = 1020;
  }
  return io::SvgDocument(width, 500, parts);
}

}  // namespace umbmark::cli
