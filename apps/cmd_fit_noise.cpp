// `umbmark fit-noise DATA... --robot R.toml [--distance D] [--meas-sigma SXY[,STH]]
//   [--plot FILE.svg] [--json FILE]`, or `umbmark fit-noise MANIFEST.toml`:
// maximum-likelihood k_L, k_R (Chong & Kleeman eq. 4) with 95% profile
// intervals and a goodness-of-fit table, from
//  - endpoint CSVs of back-and-forth runs (`--distance D`: D forward, D back),
//  - trajectory CSVs of runs of any shape (path from the ticks, return error
//    from ground truth at the first and last sample),
//  - a campaign manifest: every run with ground truth at start and end, with
//    a systematic mean per experiment and direction.
#include <algorithm>
#include <iterator>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <tuple>
#include <variant>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "common.hpp"
#include "progress.hpp"
#include "core/angles.hpp"
#include "core/errors.hpp"
#include "error_models/odometry_covariance.hpp"
#include "error_models/wheel_noise_fit.hpp"
#include "error_models/wheel_noise_fit_data.hpp"
#include "output/atomic_write.hpp"
#include "formats/file_text.hpp"
#include "report/html_report.hpp"
#include "formats/data_file.hpp"
#include "formats/manifest.hpp"
#include "formats/ros2_params.hpp"
#include "report/svg_plot.hpp"

namespace umbmark::cli {
namespace {

struct FitNoiseOptions {
  std::vector<std::string> inputs;
  RobotFlags robot;
  std::optional<double> distance_m;
  std::vector<double> meas_sigma;  // [sigma_xy_m] or [sigma_xy_m, sigma_theta_rad]
  bool first_order = false;
  bool reml = false;                  // --reml: accepted, REML is the default
  bool ml = false;                    // --ml: plain maximum likelihood
  std::string plot;
  std::string ros2;
  std::string controller = "diff_drive_controller";
  OdometryCovarianceOptions covariance;
  std::string report;
  JsonFlag json;
  std::string params_json;            // --params CAL.json: the calibrated robot
  std::string systematic = "estimate";  // estimate | none (ignored with --params)
  bool systematic_given = false;
};

/// The calibrated robot of a `calibrate --json` file: what --ros2 used
/// (outputs_use), else the refined result, else the classic one.
RobotParams CalibratedRobot(const std::string& path) {
  const std::string text = io::ReadWholeFile(path);
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(path, 0, e.byte, fmt::format("not valid JSON: {}", e.what()));
  }
  const nlohmann::json* p = nullptr;
  if (j.contains("outputs_use") && j["outputs_use"].contains("parameters")) p = &j["outputs_use"]["parameters"];
  else if (j.contains("refined") && j["refined"].contains("parameters")) p = &j["refined"]["parameters"];
  else if (j.contains("parameters")) p = &j["parameters"];
  if (!p) throw InputError(path, "no `parameters` object (expected the JSON of `umbmark calibrate --json`)");
  RobotParams r;
  try {
    r.wheelbase_m = p->at("wheelbase_m").get<double>();
    r.wheel_diameter_left_m = p->at("wheel_diameter_left_m").get<double>();
    r.wheel_diameter_right_m = p->at("wheel_diameter_right_m").get<double>();
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, fmt::format("parameters: {}", e.what()));
  }
  if (!(r.wheelbase_m > 0.0) || !(r.wheel_diameter_left_m > 0.0) || !(r.wheel_diameter_right_m > 0.0))
    throw InputError(path, "parameters must be positive");
  return r;
}

struct Loaded {
  std::vector<WheelNoiseFitRun> runs;
  std::vector<std::string> sources;
  int skipped = 0;
  double sigma_xy = 0.0, sigma_theta = 0.0;
  std::optional<double> wheelbase_m;  ///< of the (last) robot read, for --ros2
  bool ground_truth = false;  ///< trajectories or a manifest: the errors come from a ground-truth system
  SystematicErrors systematic;  ///< what the runs were built with (last input)
};

NoiseFitInputOptions InputOptions(const FitNoiseOptions& o, const std::optional<GroundTruthNoise>& manifest_gt,
                                  const RobotParams& robot, const SystematicErrors& estimated) {
  NoiseFitInputOptions in;
  in.second_order = !o.first_order;
  in.systematic = estimated;
  if (!o.params_json.empty()) {
    const RobotParams cal = CalibratedRobot(o.params_json);
    in.systematic = {cal.wheelbase_m / robot.wheelbase_m, cal.wheel_diameter_left_m / robot.wheel_diameter_left_m,
                     cal.wheel_diameter_right_m / robot.wheel_diameter_right_m};
  }
  if (!o.meas_sigma.empty()) {
    if (o.meas_sigma.size() > 2) throw InvalidOptions("--meas-sigma takes SXY or SXY,STHETA");
    in.sigma_xy_m = o.meas_sigma[0];
    in.sigma_theta_rad = o.meas_sigma.size() > 1 ? o.meas_sigma[1] : 0.0;
    if (!(in.sigma_xy_m >= 0.0) || !(in.sigma_theta_rad >= 0.0))
      throw InvalidOptions("--meas-sigma values must be >= 0");
  } else if (manifest_gt) {
    in.sigma_xy_m = manifest_gt->sigma_xy_m;
    in.sigma_theta_rad = manifest_gt->sigma_theta_rad;
  }
  return in;
}

/// Every run of a trajectory file with ground truth at its start and end.
/// Appends runs of the file that becomes the next entry of out.sources.
void AppendRuns(std::vector<WheelNoiseFitRun> runs, Loaded& out) {
  const int source = static_cast<int>(out.sources.size());
  for (WheelNoiseFitRun& r : runs) r.source = source;
  if (out.runs.empty()) {
    out.runs = std::move(runs);
    return;
  }
  out.runs.reserve(out.runs.size() + runs.size());
  std::move(runs.begin(), runs.end(), std::back_inserter(out.runs));
}

/// Every run of a trajectory file with ground truth at its start and end,
/// read run by run (memory: the fit runs, not the file's samples). The
/// runs are gathered in blocks and moved into one vector of the final size
/// (growing one vector would hold 1.5 times the runs while it reallocates).
void AppendTrajectoryRuns(io::TrajectoryReader& reader, const RobotParams& robot, const std::string& prefix,
                          const NoiseFitInputOptions& in, Loaded& out) {
  constexpr std::size_t kBlock = 1 << 15;
  std::vector<std::vector<WheelNoiseFitRun>> blocks;
  std::size_t total = 0;
  TrajectoryRun run;
  while (reader.NextRun(run)) {
    std::optional<WheelNoiseFitRun> f = NoiseRunFromTrajectory(run, reader.path(), robot, prefix, in);
    if (!f) {
      ++out.skipped;
      continue;
    }
    if (blocks.empty() || blocks.back().size() == kBlock) {
      blocks.emplace_back();
      blocks.back().reserve(kBlock);
    }
    blocks.back().push_back(std::move(*f));
    ++total;
  }
  std::vector<WheelNoiseFitRun> runs;
  runs.reserve(total);
  for (auto& b : blocks) {
    std::move(b.begin(), b.end(), std::back_inserter(runs));
    std::vector<WheelNoiseFitRun>().swap(b);
  }
  AppendRuns(std::move(runs), out);
}

void AppendManifest(const std::string& path, const FitNoiseOptions& o, const SystematicErrors& sys, Loaded& out) {
  const Manifest m = io::ReadManifest(path);
  const RobotParams robot = o.robot.Resolve(m.robot);
  out.wheelbase_m = robot.wheelbase_m;
  const NoiseFitInputOptions in = InputOptions(o, m.ground_truth, robot, sys);
  out.ground_truth = true;
  out.systematic = in.systematic;
  out.sigma_xy = in.sigma_xy_m;
  out.sigma_theta = in.sigma_theta_rad;
  int index = 0;
  for (const Experiment& e : m.experiments) {
    ++index;
    const std::string prefix = fmt::format("exp{}:{}:", index, ExperimentKindToString(e.kind));
    io::OpenedRunFile rf = io::OpenRunFile(e.resolved_file);
    if (auto* t = std::get_if<io::TrajectoryReader>(&rf)) {
      AppendTrajectoryRuns(*t, robot, prefix, in, out);
    } else {
      const auto& ep = std::get<EndpointData>(rf);
      if (e.kind == ExperimentKind::kBackAndForth) {
        AppendRuns(NoiseRunsFromEndpoints(ep, BackAndForthPath(e.distance_m), robot.wheelbase_m, prefix, in), out);
      } else if (e.kind == ExperimentKind::kSquare) {
        for (const bool cw : {true, false}) {  // one path per direction
          EndpointData part{ep.path, {}};
          for (const auto& r : ep.runs) {
            if (r.direction != "cw" && r.direction != "ccw")
              throw InputError(ep.path, r.line, 0, fmt::format("square run direction '{}' must be cw or ccw", r.direction));
            if ((r.direction == "cw") == cw) part.runs.push_back(r);
          }
          AppendRuns(NoiseRunsFromEndpoints(part, SquarePath(e.side_m, cw), robot.wheelbase_m, prefix, in), out);
        }
      } else {
        throw InputError(e.resolved_file, "a 'free' experiment needs a trajectory CSV (its path comes from the ticks)");
      }
    }
    out.sources.push_back(e.resolved_file);
  }
}

Loaded Load(const FitNoiseOptions& o, const SystematicErrors& sys = {}) {
  Loaded out;
  for (const std::string& path : o.inputs) {
    if (io::IsManifestPath(path)) {
      AppendManifest(path, o, sys, out);
      continue;
    }
    const RobotParams robot = o.robot.Resolve();
    out.wheelbase_m = robot.wheelbase_m;
    const NoiseFitInputOptions in = InputOptions(o, std::nullopt, robot, sys);
    out.systematic = in.systematic;
    out.sigma_xy = in.sigma_xy_m;
    out.sigma_theta = in.sigma_theta_rad;
    const std::string prefix = o.inputs.size() > 1 ? path + ":" : "";
    io::OpenedRunFile rf = io::OpenRunFile(path);
    if (auto* t = std::get_if<io::TrajectoryReader>(&rf)) {
      AppendTrajectoryRuns(*t, robot, prefix, in, out);
      out.ground_truth = true;
    } else {
      if (!o.distance_m)
        throw InvalidOptions(path + " holds endpoint errors: give --distance D (each run drove D forward, then D back)");
      AppendRuns(NoiseRunsFromEndpoints(std::get<EndpointData>(rf), BackAndForthPath(*o.distance_m),
                                        robot.wheelbase_m, prefix, in),
                 out);
    }
    out.sources.push_back(path);
  }
  MergeLoneTurnGroups(out.runs);
  return out;
}

nlohmann::json JsonMatrix(const PoseCovariance& P) {
  nlohmann::json rows = nlohmann::json::array();
  for (int i = 0; i < 3; ++i) rows.push_back({P(i, 0), P(i, 1), P(i, 2)});
  return rows;
}

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

/// The fit and the systematic errors it used.
struct FitResult {
  WheelNoiseFitSummary s;
  SystematicErrors systematic;
  std::string source;                      ///< "estimated", "params" or "none"
  std::optional<SystematicEstimate> estimate;  ///< when estimated
  bool kL_determined = true, kR_determined = true;
};

/// Which experiment would determine an undetermined k (`name` is "k_L" or
/// "k_R"), as a clause.
std::string DetermineKExperiment(const FitResult& f, const std::string& name) {
  const bool other = name == "k_L" ? f.kR_determined : f.kL_determined;
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
std::string UndeterminedK(const FitResult& f, const std::string& name) {
  const double upper = name == "k_L" ? f.s.k_L_ci[1] : f.s.k_R_ci[1];
  return fmt::format("{} is not determined by these runs (its estimate sits at the boundary 0), {}; {}", name,
                     KBound(name, upper), DetermineKExperiment(f, name));
}

/// The HTML page; `warnings`, `notes`: the JSON's (shown as in the text).
std::string FitNoiseReportHtml(const std::vector<std::string>& inputs, const FitResult& f,
                               const std::string& svg, const std::vector<std::string>& warnings,
                               const std::vector<std::string>& notes) {
  std::string subject;
  for (const auto& i : inputs) subject += (subject.empty() ? "" : ", ") + i;
  const WheelNoiseFitSummary& s = f.s;
  io::HtmlReport rep("umbmark fit-noise", subject);
  bool flagged = false;
  for (const auto& g : s.goodness_of_fit) flagged |= std::abs(g.z) > 3.0;
  // An undetermined k has no interval, only an upper bound: "0 to x" would
  // read as a measured range.
  auto k_text = [](const char* name, double k, bool determined, const std::array<double, 2>& ci) {
    return determined ? fmt::format("{} = {:.3g} m^1/2 (95%: {:.3g} to {:.3g})", name, k, ci[0], ci[1])
                      : fmt::format("{} not determined ({})", name, KBound(name, ci[1]));
  };
  const bool all = f.kL_determined && f.kR_determined;
  rep.Headline(fmt::format("Wheel noise {}, {} from {} runs{}.", k_text("k_L", s.k_L, f.kL_determined, s.k_L_ci),
                           k_text("k_R", s.k_R, f.kR_determined, s.k_R_ci), s.runs,
                           flagged ? "; the model does not explain every element of the scatter" : ""),
               flagged || !all ? io::HtmlReport::Level::kWarn : io::HtmlReport::Level::kGood);
  std::vector<std::string> steps;
  for (const char* name : {"k_L", "k_R"})
    if (!(std::string(name) == "k_L" ? f.kL_determined : f.kR_determined))
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

/// Step 2: k_L, k_R with the systematic errors estimated jointly (default),
/// given by --params, or none (a calibrated robot).
FitResult Fit(const FitNoiseOptions& o, Loaded& data) {
  WheelNoiseFitOptions fo;
  fo.restricted = !o.ml;
  fo.sources = data.sources;
  FitResult f;
  if (!o.params_json.empty()) {
    f.source = "params";
  } else {
    f.source = o.systematic == "none" ? "none" : "estimated";
  }
  f.systematic = data.systematic;
  Progress progress(fmt::format("fitting k_L, k_R to {} runs", data.runs.size()));
  fo.progress = progress.Callback();
  if (f.source == "estimated") {
    // The joint fit rebuilds the runs' bases in place (the data are read once).
    SystematicEstimate e;
    f.s = FitWheelNoiseWithSystematics(data.runs, fo, &e);
    f.estimate = e;
    f.systematic = e.value;
  } else {
    f.s = FitWheelNoise(data.runs, fo);
  }
  // k at its boundary 0: the data bound it from above only.
  auto determined = [](double k, const std::array<double, 2>& ci) { return !(ci[0] <= 0.0 && k < 0.01 * ci[1]); };
  f.kL_determined = determined(f.s.k_L, f.s.k_L_ci);
  f.kR_determined = determined(f.s.k_R, f.s.k_R_ci);
  return f;
}

std::vector<std::string> Warnings(const Loaded& data, const FitResult& f) {
  std::vector<std::string> warnings;
  if (data.ground_truth && data.sigma_xy == 0.0 && data.sigma_theta == 0.0) {
    warnings.push_back(
        "the reference noise is 0 although the return errors come from a ground-truth system: its noise is then read "
        "as wheel noise and k comes out high; give --meas-sigma SXY,STHETA (or the manifest's [ground_truth])");
  }
  if (f.estimate && !f.estimate->E_d_determined) {
    warnings.push_back(fmt::format(
        "the scatter pulled E_d more than {} from the value the group means give, so E_d was kept at {:.5f}: the "
        "noise model does not fit these runs well (see the goodness of fit) or the design does not show E_d; give "
        "--params CAL.json from `umbmark calibrate` (or --systematic none for a calibrated robot)",
        kMaxJointEdShift, f.systematic.c_R / f.systematic.c_L));
  }
  if (!f.kL_determined) warnings.push_back(UndeterminedK(f, "k_L"));
  if (!f.kR_determined) warnings.push_back(UndeterminedK(f, "k_R"));
  return warnings;
}

/// What the reader should know about the systematic errors' estimate
/// (text, JSON `notes`, HTML).
std::vector<std::string> Notes(const FitResult& f) {
  std::vector<std::string> notes;
  if (!f.estimate) return notes;
  if (f.estimate->E_d_determined && f.estimate->E_d_se > 0.5 * WheelNoiseFitOptions{}.E_d_prior_sigma)
    notes.push_back(fmt::format("the scatter of this design barely shows E_d (+- {:.4f}, near the prior's {}); the "
                                "intervals include that uncertainty: give --params CAL.json for narrower ones",
                                f.estimate->E_d_se, WheelNoiseFitOptions{}.E_d_prior_sigma));
  if (!f.estimate->E_b_determined) {
    const std::string why =
        f.estimate->turns
            ? fmt::format("the runs' mean return errors determine E_b only to +- {:.3f} (the prior's 0.05: too few "
                          "runs per direction, or too much scatter, for the turns to show it)",
                          f.estimate->E_b_se)
            : std::string("this design (no turns) does not show E_b");
    notes.push_back(why + "; k is relative to the recorded wheelbase (a wheelbase off by x % moves k by up to x %): "
                          "give --params CAL.json from `umbmark calibrate`");
  }
  return notes;
}

/// The JSON document (contract keys first).
nlohmann::json ResultJson(const FitNoiseOptions& o, const Loaded& data, const FitResult& f) {
  const WheelNoiseFitSummary& s = f.s;
  nlohmann::json gof = nlohmann::json::array();
  for (const auto& g : s.goodness_of_fit)
    gof.push_back({{"element", g.element},
                   {"observed", g.observed},
                   {"predicted", g.predicted},
                   {"standard_error", g.standard_error},
                   {"z", g.z},
                   {"runs", g.runs}});
  std::map<std::string, int> per_group;
  for (const int g : s.group_of_run) ++per_group[s.groups[static_cast<std::size_t>(g)]];
  nlohmann::json groups = nlohmann::json::array();
  for (std::size_t g = 0; g < s.groups.size(); ++g) {
    groups.push_back({{"group", s.groups[g]},
                      {"runs", per_group[s.groups[g]]},
                      {"systematic_mean", {s.group_means[g](0), s.group_means[g](1), s.group_means[g](2)}}});
  }
  nlohmann::json j = {{"k_L", s.k_L},
                      {"k_R", s.k_R},
                      {"k_L_ci95", {JsonNumber(s.k_L_ci[0]), JsonNumber(s.k_L_ci[1])}},
                      {"k_R_ci95", {JsonNumber(s.k_R_ci[0]), JsonNumber(s.k_R_ci[1])}},
                      {"runs", s.runs},
                      {"skipped_runs", data.skipped},
                      {"groups", groups},
                      {"meas_sigma", {data.sigma_xy, data.sigma_theta}},
                      {"second_order", !o.first_order},
                      {"restricted", !o.ml},
                      {"neg_log_likelihood", s.neg_log_likelihood},
                      {"goodness_of_fit", gof},
                      {"observed_covariance", JsonMatrix(s.observed_covariance)},
                      {"predicted_covariance", JsonMatrix(s.predicted_covariance)},
                      {"inputs", data.sources}};
  j["k_L_determined"] = f.kL_determined;
  j["k_R_determined"] = f.kR_determined;
  j["k_L_upper95"] = JsonNumber(s.k_L_ci[1]);
  j["k_R_upper95"] = JsonNumber(s.k_R_ci[1]);
  const SystematicErrors& used = f.systematic;
  j["systematic_errors"] = {{"source", f.source},
                            {"E_b", used.E_b},
                            {"c_L", used.c_L},
                            {"c_R", used.c_R},
                            {"E_d", used.c_R / used.c_L}};
  if (f.estimate) {
    j["systematic_errors"]["E_d_se"] = f.estimate->E_d_se;
    j["systematic_errors"]["E_b_se"] = f.estimate->E_b_se;
    j["systematic_errors"]["E_b_determined"] = f.estimate->E_b_determined;
    j["systematic_errors"]["E_d_determined"] = f.estimate->E_d_determined;
  }
  j["likelihood_passes"] = s.likelihood_passes;
  j["warnings"] = Warnings(data, f);
  j["notes"] = Notes(f);
  return j;
}

void PrintText(const FitNoiseOptions& o, const Loaded& data, const FitResult& f, const nlohmann::json& j) {
  const WheelNoiseFitSummary& s = f.s;
  fmt::print("fit-noise: {} runs in {} group(s){}\n", s.runs, s.groups.size(),
             data.skipped ? fmt::format(" ({} runs without ground truth at both ends skipped)", data.skipped) : "");
  for (const auto& [name, k, det, ci] :
       {std::tuple{"k_L", s.k_L, f.kL_determined, s.k_L_ci}, std::tuple{"k_R", s.k_R, f.kR_determined, s.k_R_ci}}) {
    if (det) {
      fmt::print("  {} = {:.4g} m^1/2   95% interval [{:.4g}, {:.4g}]\n", name, k, ci[0], ci[1]);
    } else {
      fmt::print("  {} not determined (at the boundary 0); 95% upper bound {} (a bound only: see the warning for the "
                 "runs that would determine it)\n",
                 name, std::isfinite(ci[1]) ? fmt::format("{:.4g} m^1/2", ci[1]) : std::string("none"));
    }
  }
  if (f.estimate) {
    const SystematicErrors& e = f.systematic;
    fmt::print("  systematic errors estimated jointly: E_d = {:.5f}{}, E_b = {:.5f}{}\n", e.c_R / e.c_L,
               f.estimate->E_d_determined ? fmt::format(" +- {:.5f} (from the means and the scatter)", f.estimate->E_d_se)
                                          : std::string(" (from the means; see the warning)"),
               e.E_b,
               f.estimate->E_b_determined ? fmt::format(" +- {:.5f} (from the means)", f.estimate->E_b_se) : "");
    for (const auto& n : j["notes"]) fmt::print("  note: {}\n", n.get<std::string>());
  } else if (f.source == "params") {
    fmt::print("  systematic errors from {}\n", o.params_json);
  } else {
    fmt::print("  systematic errors: none assumed (--systematic none: the robot is calibrated)\n");
  }
  fmt::print("  reference noise per pose: {:.3g} m, {:.3g} rad; model: {} order, {}\n", data.sigma_xy,
             data.sigma_theta, o.first_order ? "first" : "second", o.ml ? "ML" : "REML");
  fmt::print("Systematic mean per group (ex [mm], ey [mm], etheta [mrad]):\n");
  for (std::size_t g = 0; g < s.groups.size(); ++g)
    fmt::print("  {:<40} {:>9.3f} {:>9.3f} {:>9.3f}\n", s.groups[g], 1e3 * s.group_means[g](0),
               1e3 * s.group_means[g](1), 1e3 * s.group_means[g](2));
  fmt::print("Goodness of fit (residual covariance, observed vs model):\n");
  fmt::print("  {:<6} {:>13} {:>13} {:>13} {:>7} {:>5}\n", "elem", "observed", "predicted", "std.error", "z", "runs");
  bool flagged = false;
  for (const auto& g : s.goodness_of_fit) {
    const bool bad = std::abs(g.z) > 3.0;
    flagged |= bad;
    fmt::print("  {:<6} {:>13.4e} {:>13.4e} {:>13.4e} {:>7.2f} {:>5}{}\n", g.element, g.observed, g.predicted,
               g.standard_error, g.z, g.runs, bad ? "  <- not explained by the model" : "");
  }
  if (flagged) fmt::print("  |z| > 3: the wheel noise model cannot explain that element (see docs/noise-model.md)\n");
  for (const auto& w : j["warnings"]) fmt::print("  WARNING: {}\n", w.get<std::string>());
}

/// The k_L, k_R that --ros2 turns into a covariance. A k at its boundary 0
/// (not determined) would give a covariance that trusts that wheel almost
/// perfectly (4e-10 m^2 pose variance on the README's square campaign), so
/// an undetermined k is replaced by its 95 % upper bound (a conservative
/// covariance; said in the YAML comment and the warnings).
struct Ros2Noise {
  double k_L = 0.0, k_R = 0.0;
  std::string kL_source = "estimate", kR_source = "estimate";  ///< "estimate" or "upper95"
  std::vector<std::string> comments;                           ///< YAML comment lines
};

/// An upper bound above this [m^1/2] says nothing about a wheel: its travel
/// error after 1 m would be 5 cm, 10 to 100 times the k of Chong & Kleeman's
/// robot (4e-4 to 6e-4) and of the robots in data/ (up to 8e-3).
constexpr double kMaxUsefulKBound = 0.05;

/// Ros2Noise of a fit; throws QualityGateError (exit 3, before anything is
/// written) when an undetermined k has no useful upper bound either.
Ros2Noise Ros2NoiseOf(const FitNoiseOptions& o, const FitResult& f) {
  Ros2Noise r{f.s.k_L, f.s.k_R, "estimate", "estimate", {}};
  for (const auto& [name, determined, upper, k, source] :
       {std::tuple{"k_L", f.kL_determined, f.s.k_L_ci[1], &r.k_L, &r.kL_source},
        std::tuple{"k_R", f.kR_determined, f.s.k_R_ci[1], &r.k_R, &r.kR_source}}) {
    if (determined) continue;
    if (!(upper <= kMaxUsefulKBound))
      throw QualityGateError(fmt::format(
          "fit-noise --ros2 {}: {} is not determined by these {} runs ({}), so no covariance is written; drive more "
          "runs (back-and-forth runs, 10 m forward and back, 20 or more, determine both k), give the reference's "
          "noise with --meas-sigma SXY,STHETA (or the manifest's [ground_truth]){}",
          o.ros2, name, f.s.runs,
          std::isfinite(upper) ? fmt::format("its 95 % upper bound {:.3g} m^1/2 says nothing about a wheel", upper)
                               : std::string("not even bounded from above"),
          f.source == "estimated"
              ? ", or give the calibration (--params CAL.json from `umbmark calibrate --json`) so that E_d is not "
                "estimated from the same few runs"
              : ""));
    *k = upper;
    *source = "upper95";
    r.comments.push_back(fmt::format("{} is not determined by the runs (its estimate sits at 0): its 95 % upper bound "
                                     "{:.4g} m^1/2 is used, so this covariance is conservative",
                                     name, upper));
  }
  return r;
}

/// The warning --ros2 adds for each k it replaced by its upper bound.
std::vector<std::string> Ros2Warnings(const FitNoiseOptions& o, const FitResult& f) {
  std::vector<std::string> out;
  if (o.ros2.empty()) return out;
  const Ros2Noise k = Ros2NoiseOf(o, f);
  for (const auto& [name, source, value] :
       {std::tuple{"k_L", k.kL_source, k.k_L}, std::tuple{"k_R", k.kR_source, k.k_R}})
    if (source == "upper95")
      out.push_back(fmt::format("--ros2 {}: {} is not determined, so its 95 % upper bound {:.4g} m^1/2 is written "
                                "(a conservative covariance; back-and-forth runs and --meas-sigma would determine it)",
                                o.ros2, name, value));
  return out;
}

/// --plot, --report, --ros2; returns what was written.
std::vector<std::string> WriteOutputs(const FitNoiseOptions& o, const Loaded& data, const FitResult& f,
                                      nlohmann::json& j) {
  const WheelNoiseFitSummary& s = f.s;
  std::vector<std::string> written;
  std::string svg;
  if (!o.plot.empty() || !o.report.empty()) svg = PlotSvg(s);
  if (!o.plot.empty()) {
    CommandOutputs().Write(o.plot, svg);
    written.push_back(o.plot + " (plot)");
  }
  if (!o.report.empty()) {
    CommandOutputs().Write(o.report, FitNoiseReportHtml(o.inputs, f, svg, j["warnings"], j["notes"]));
    written.push_back(o.report + " (HTML report)");
  }
  if (o.ros2.empty()) return written;
  // diff_drive_controller covariance diagonals from the fitted noise (an
  // undetermined k at its 95 % upper bound, Ros2Noise).
  const Ros2Noise k = Ros2NoiseOf(o, f);
  const OdometryCovariance cov = OdometryCovarianceFromWheelNoise(k.k_L, k.k_R, *data.wheelbase_m, o.covariance);
  std::vector<std::string> comment{
      fmt::format("ros2_control diff_drive_controller covariance from umbmark fit-noise: k_L = {:.4g}, k_R = {:.4g} "
                  "m^1/2, wheelbase {} m", k.k_L, k.k_R, *data.wheelbase_m)};
  comment.insert(comment.end(), k.comments.begin(), k.comments.end());
  comment.push_back(fmt::format("stated for {} m/s at {} Hz updates (variances scale with speed; derivation: docs/ros2.md)",
                                o.covariance.speed_mps, o.covariance.rate_hz));
  comment.push_back(fmt::format("{} = not measured by planar odometry (z, roll, pitch and rates); {} = lateral velocity "
                                "(non-holonomic constraint)", kUnmeasuredVariance, kConstraintVariance));
  CommandOutputs().Write(o.ros2, io::FormatDiffDriveCovariance(o.controller, cov.pose, cov.twist, comment));
  j["ros2"] = {{"file", o.ros2},
               {"controller", o.controller},
               {"rate_hz", o.covariance.rate_hz},
               {"speed_mps", o.covariance.speed_mps},
               {"k_L", k.k_L},
               {"k_R", k.k_R},
               {"k_L_source", k.kL_source},
               {"k_R_source", k.kR_source},
               {"pose_covariance_diagonal", cov.pose},
               {"twist_covariance_diagonal", cov.twist}};
  if (o.json.PrintText())
    fmt::print("  wrote {} (diff_drive_controller covariance at {} m/s, {} Hz)\n", o.ros2, o.covariance.speed_mps,
               o.covariance.rate_hz);
  return written;
}

// The command's steps: register files, read, fit, JSON, text, outputs.
int RunFitNoise(const FitNoiseOptions& o) {
  io::OutputSet& outs = CommandOutputs();
  RegisterInputs(o.inputs, &o.robot);
  if (!o.params_json.empty()) outs.AddInput(o.params_json);
  outs.AddOutput("--json", o.json.path);
  outs.AddOutput("--plot", o.plot);
  outs.AddOutput("--report", o.report);
  outs.AddOutput("--ros2", o.ros2);
  outs.Check();
  if (!o.params_json.empty() && o.systematic == "estimate" && o.systematic_given)
    throw InvalidOptions("--params and --systematic estimate contradict each other (give one)");
  if (o.ml && o.reml) throw InvalidOptions("--ml and --reml contradict each other (give one)");
  Loaded data = Load(o);
  if (data.runs.empty()) throw InputError(o.inputs.front(), "no run with ground truth at its start and end");
  if (!o.ros2.empty() && !data.wheelbase_m)
    throw InvalidOptions("--ros2 needs the robot's wheelbase (--robot or --wheelbase)");
  const FitResult f = Fit(o, data);
  nlohmann::json j = ResultJson(o, data, f);
  for (const std::string& w : Ros2Warnings(o, f)) j["warnings"].push_back(w);  // throws (exit 3) before any output
  if (o.json.PrintText()) {
    PrintText(o, data, f, j);
  } else {
    for (const auto& w : j["warnings"]) fmt::print(stderr, "fit-noise: warning: {}\n", w.get<std::string>());
  }
  std::vector<std::string> written = WriteOutputs(o, data, f, j);
  o.json.Emit(j);
  if (!o.json.path.empty() && !o.json.ToStdout()) written.push_back(o.json.path + " (JSON)");
  PrintWritten(written, o.json.PrintText());
  return 0;
}

}  // namespace

Command SetupFitNoise(CLI::App& parent) {
  auto opts = std::make_shared<FitNoiseOptions>();
  auto* app = parent.add_subcommand("fit-noise", "k_L, k_R (Chong & Kleeman) from back-and-forth or any trajectory runs");
  app->add_option("DATA", opts->inputs, "Endpoint or trajectory CSV(s), or campaign manifest(s)")
      ->required();
  opts->robot.Bind(*app);
  app->add_option("--distance", opts->distance_m, "Endpoint data: each run drove D forward, then D back [m]")
      ->check(Plausible("distance_m"));
  app->add_option("--meas-sigma", opts->meas_sigma,
                  "Noise of the external reference per measured pose: SXY[,STHETA] [m, rad] (default: the "
                  "manifest's [ground_truth], else 0)")
      ->delimiter(',');
  app->add_flag("--first-order", opts->first_order, "Fit the first-order model only (no heading-squared term)");
  app->add_flag("--reml", opts->reml,
                "Restricted maximum likelihood, allowing for the fitted systematic means (the default)");
  app->add_flag("--ml", opts->ml, "Plain maximum likelihood instead of REML (k about 1 % low with 60 runs)");
  app->add_option("--plot", opts->plot,
                  "Write an SVG: per group the runs with observed and fitted 95% ellipses about the group mean");
  app->add_option("--report", opts->report, "Write a self-contained HTML report (k_L, k_R with intervals, checks, plots)");
  app->add_option("--ros2", opts->ros2,
                  "Write diff_drive_controller pose/twist_covariance_diagonal from k_L, k_R (YAML; docs/ros2.md)");
  app->add_option("--controller", opts->controller, "Controller name at the top of the --ros2 file")->capture_default_str();
  app->add_option("--rate", opts->covariance.rate_hz, "--ros2: odometry update rate [Hz]")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app->add_option("--speed", opts->covariance.speed_mps, "--ros2: driving speed the covariance is stated for [m/s]")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app->add_option("--params", opts->params_json,
                  "The robot's calibration (JSON of `calibrate --json`): the noise is propagated along the path the "
                  "calibrated robot really drove, so uncorrected systematic errors do not bias k")
      ->check(CLI::ExistingFile);
  app->add_option("--systematic", opts->systematic,
                  "estimate: estimate E_d (from the means and the scatter) and E_b (from the means) jointly with k, so k is unbiased "
                  "on an uncalibrated robot; none: assume a calibrated robot (the odometry's path). Ignored with --params")
      ->check(CLI::IsMember({"none", "estimate"}))
      ->capture_default_str()
      ->each([opts](const std::string&) { opts->systematic_given = true; });
  opts->json.Bind(*app);
  return {app, [opts] { return RunFitNoise(*opts); }};
}

}  // namespace umbmark::cli
