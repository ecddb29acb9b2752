// The figure and HTML page of `fit-noise --plot/--report` (see
// fit_noise_report.hpp).
#include "api/fit_noise_report.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "report/html_report.hpp"
#include "report/svg_plot.hpp"

namespace umbmark::api {

/// Which experiment would determine an undetermined k (`name` is "k_L" or
/// "k_R"), as a clause.
std::string DetermineKExperiment(const FitNoiseResult& f, const std::string& name) {
  const bool other = name == "k_L" ? f.k_R_determined : f.k_L_determined;
  // With the other k determined the runs show the total wheel noise but not
  // how it splits between the wheels: straight runs and spot turns move both
  // wheels the same distance, and only Cov(x, theta) tells them apart.
  return other ? "runs in which the two wheels travel different distances (arcs or circles in both directions, pivot "
                 "turns on each wheel) separate k_L from k_R"
               : "the wheel noise is below what the reference noise lets these runs show: longer runs (wheel noise "
                 "grows with distance, the reference noise does not) or a more precise reference would determine it";
}

/// What bounds an undetermined k: "k_L < x m^1/2 at 95 %", or nothing when
/// the profile likelihood never falls far enough (the reference noise
/// swamps the wheel noise).
std::string KBound(const std::string& name, double upper) {
  return std::isfinite(upper) ? fmt::format("only bounded: {} < {:.3g} m^1/2 at 95 %", name, upper)
                              : std::string("not even bounded from above: the likelihood stays flat");
}

/// What bounds an undetermined k and what would determine it: the JSON
/// warning (also printed in the text and the HTML).
std::string UndeterminedK(const FitNoiseResult& f, const std::string& name) {
  const double upper = name == "k_L" ? f.fit.k_L_ci[1] : f.fit.k_R_ci[1];
  return fmt::format("{} is not determined by these runs (its estimate sits at the boundary 0), {}; {}", name,
                     KBound(name, upper), DetermineKExperiment(f, name));
}

namespace {

/// Figure 4 of Chong & Kleeman, per group: each run's return error, and for
/// each group (experiment and direction) its observed 95% ellipse (solid)
/// and the fitted model's (dashed), both about the group's own systematic
/// mean; for ex-ey, ex-etheta, ey-etheta.
std::string PlotSvg(const WheelNoiseFitSummary& s) {
  const double scale95 = std::sqrt(-2.0 * std::log(0.05));  // 2-D 95% ellipse: sqrt(chi^2_2(0.95))
  const double unit[3] = {1e3, 1e3, 1e3};                      // mm, mm, mrad
  const char* label[3] = {"e_x [mm]", "e_y [mm]", "e_theta [mrad]"};
  const int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
  const char* colors[] = {"#1f5fa8", "#c0392b", "#1f7a3a", "#7d3c98", "#b9770e", "#555555"};
  const char* markers[] = {"circle", "triangle", "square", "diamond", "plus", "cross"};
  const std::size_t G = s.groups.size();
  // Per group: members, observed covariance of residuals, mean predicted covariance.
  std::vector<std::vector<std::size_t>> members(G);
  for (std::size_t i = 0; i < s.group_of_run.size() && i < s.residuals.size(); ++i)
    members[static_cast<std::size_t>(s.group_of_run[i])].push_back(i);
  std::vector<PoseCovariance> observed(G, PoseCovariance::Zero()), predicted(G, PoseCovariance::Zero());
  for (std::size_t g = 0; g < G; ++g) {
    const double n = static_cast<double>(members[g].size());
    for (std::size_t i : members[g]) {
      observed[g] += s.residuals[i] * s.residuals[i].transpose() / std::max(n - 1.0, 1.0);
      if (i < s.predicted_run_covariance.size()) predicted[g] += s.predicted_run_covariance[i] / n;
    }
  }
  std::vector<std::string> parts;
  const double size = 340;
  double bottom = 0;
  for (int k = 0; k < 3; ++k) {
    const int a = pairs[k][0], b = pairs[k][1];
    io::SvgPanel p(80 + k * (size + 90), 50, size, size, fmt::format("{} vs {}", label[b], label[a]));
    std::vector<io::SvgPoint> extent;
    std::vector<std::vector<io::SvgPoint>> pts(G);
    for (std::size_t g = 0; g < G; ++g) {
      const Eigen::Vector3d& mu = s.group_means[g];
      for (std::size_t i : members[g]) {
        const Eigen::Vector3d e = mu + s.residuals[i];
        if (std::isfinite(e(a)) && std::isfinite(e(b))) pts[g].push_back({e(a) * unit[a], e(b) * unit[b]});
      }
      extent.insert(extent.end(), pts[g].begin(), pts[g].end());
      for (const PoseCovariance* C : {&observed[g], &predicted[g]}) {
        const double rx = scale95 * std::sqrt(std::max((*C)(a, a), 0.0)) * unit[a];
        const double ry = scale95 * std::sqrt(std::max((*C)(b, b), 0.0)) * unit[b];
        extent.push_back({mu(a) * unit[a] + rx, mu(b) * unit[b] + ry});
        extent.push_back({mu(a) * unit[a] - rx, mu(b) * unit[b] - ry});
      }
    }
    p.FitExtent(extent, false, false);
    p.Axes(label[a], label[b]);
    std::vector<std::pair<io::SvgStyle, std::string>> legend;
    for (std::size_t g = 0; g < G; ++g) {
      const io::SvgStyle dots{colors[g % 6], markers[g % 6], "", 1.5, g % 2 == 0};
      const io::SvgStyle obs{colors[g % 6], "", "", 1.6, false}, pred{colors[g % 6], "", "6,4", 1.6, false};
      const Eigen::Vector3d& mu = s.group_means[g];
      const io::SvgPoint c{mu(a) * unit[a], mu(b) * unit[b]};
      const PoseCovariance& O = observed[g];
      const PoseCovariance& P = predicted[g];
      p.Points(pts[g], dots, 3.0);
      p.CovarianceEllipse(c, O(a, a) * unit[a] * unit[a], O(a, b) * unit[a] * unit[b], O(b, b) * unit[b] * unit[b],
                          scale95, obs);
      p.CovarianceEllipse(c, P(a, a) * unit[a] * unit[a], P(a, b) * unit[a] * unit[b], P(b, b) * unit[b] * unit[b],
                          scale95, pred);
      if (k == 0) {
        legend.push_back({dots, fmt::format("{} ({} runs)", s.groups[g], members[g].size())});
        legend.push_back({obs, "  observed 95% ellipse about the group mean"});
        legend.push_back({pred, fmt::format("  model 95% ellipse (k_L = {:.3g}, k_R = {:.3g} m^1/2)", s.k_L, s.k_R)});
      }
    }
    if (k == 0) p.Legend(legend);
    bottom = std::max(bottom, p.Bottom());
    parts.push_back(p.Render());
  }
  return io::SvgDocument(3 * (size + 90) + 60, bottom + 10, parts);
}

}  // namespace

std::string FitNoisePlotSvg(const FitNoiseResult& result) { return PlotSvg(result.fit); }

std::string FitNoiseReportHtml(const FitNoiseResult& f, const std::vector<std::string>& inputs, const std::string& svg) {
  const std::vector<std::string>& warnings = f.warnings;
  const std::vector<std::string>& notes = f.notes;
  std::string subject;
  for (const auto& i : inputs) subject += (subject.empty() ? "" : ", ") + i;
  const WheelNoiseFitSummary& s = f.fit;
  io::HtmlReport rep("umbmark fit-noise", subject);
  bool flagged = false;
  for (const auto& g : s.goodness_of_fit) flagged |= std::abs(g.z) > 3.0;
  // An undetermined k has no interval, only an upper bound: "0 to x" would
  // read as a measured range.
  auto k_text = [](const char* name, double k, bool determined, const std::array<double, 2>& ci) {
    return determined ? fmt::format("{} = {:.3g} m^1/2 (95%: {:.3g} to {:.3g})", name, k, ci[0], ci[1])
                      : fmt::format("{} not determined ({})", name, KBound(name, ci[1]));
  };
  const bool all = f.k_L_determined && f.k_R_determined;
  rep.Headline(fmt::format("Wheel noise {}, {} from {} runs{}.", k_text("k_L", s.k_L, f.k_L_determined, s.k_L_ci),
                           k_text("k_R", s.k_R, f.k_R_determined, s.k_R_ci), s.runs,
                           flagged ? "; the model does not explain every element of the scatter" : ""),
               flagged || !all ? io::HtmlReport::Level::kWarn : io::HtmlReport::Level::kGood);
  std::vector<std::string> steps;
  for (const char* name : {"k_L", "k_R"})
    if (!(std::string(name) == "k_L" ? f.k_L_determined : f.k_R_determined))
      steps.push_back(fmt::format("To determine {}: {}.", name, DetermineKExperiment(f, name)));
  steps.push_back(all ? "Use k_L, k_R in `umbmark predict` (pose covariance after any path) or in your simulator (wheel "
                        "travel variance k^2 |travel|)."
                      : "Until then, an undetermined k's upper bound (where there is one) is the conservative value for "
                        "`umbmark predict` or your simulator (wheel travel variance k^2 |travel|).");
  if (flagged) steps.push_back("An element with |z| > 3 is not explained by white wheel noise: run `umbmark diagnose` on the campaign.");
  if (s.runs < 20) steps.push_back("Intervals are wide with few runs: 20 or more runs per group narrow them.");
  rep.NextSteps(steps);
  rep.Warnings(warnings);
  if (!notes.empty()) {
    rep.Heading("Notes");
    for (const auto& n : notes) rep.Paragraph(n);
  }
  rep.Heading("Systematic mean per group");
  std::vector<std::vector<std::string>> rows;
  for (std::size_t g = 0; g < s.groups.size(); ++g)
    rows.push_back({s.groups[g], fmt::format("{:.3f}", 1e3 * s.group_means[g](0)), fmt::format("{:.3f}", 1e3 * s.group_means[g](1)),
                    fmt::format("{:.3f}", 1e3 * s.group_means[g](2))});
  rep.Table({"group", "e_x [mm]", "e_y [mm]", "e_theta [mrad]"}, rows);
  rep.Heading("Goodness of fit: residual covariance, observed vs model");
  rows.clear();
  for (const auto& g : s.goodness_of_fit)
    rows.push_back({g.element, fmt::format("{:.4e}", g.observed), fmt::format("{:.4e}", g.predicted),
                    fmt::format("{:.4e}", g.standard_error), fmt::format("{:+.2f}", g.z), std::to_string(g.runs)});
  rep.Table({"element (m^2, m rad, rad^2)", "observed", "model", "standard error", "z", "runs"}, rows);
  rep.Heading("Plots");
  rep.Figure(svg, "Each run's return error; per group the observed 95% ellipse (solid) and the fitted model's (dashed), "
                  "about the group's own mean.");
  return rep.Render();
}

}  // namespace umbmark::api
