// `umbmark fit-noise DATA... --robot R.toml [--distance D] [--meas-sigma SXY[,STH]]
//   [--plot FILE.svg] [--json FILE]`, or `umbmark fit-noise MANIFEST.toml`:
// maximum-likelihood k_L, k_R (Chong & Kleeman eq. 4) with 95% profile
// intervals and a goodness-of-fit table, from
//  - endpoint CSVs of back-and-forth runs (`--distance D`: D forward, D back),
//  - trajectory CSVs of runs of any shape (path from the ticks, return error
//    from ground truth at the first and last sample),
//  - a campaign manifest: every run with ground truth at start and end, with
//    a systematic mean per experiment and direction.
#include <memory>
#include <optional>
#include <tuple>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "api/fit_noise.hpp"
#include "api/fit_noise_report.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "progress.hpp"
#include "core/errors.hpp"

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

void PrintText(const FitNoiseOptions& o, const api::FitNoiseResult& f) {
  const WheelNoiseFitSummary& s = f.fit;
  fmt::print("fit-noise: {} runs in {} group(s){}\n", s.runs, s.groups.size(),
             f.skipped_runs ? fmt::format(" ({} runs without ground truth at both ends skipped)", f.skipped_runs) : "");
  for (const auto& [name, k, det, ci] :
       {std::tuple{"k_L", s.k_L, f.k_L_determined, s.k_L_ci}, std::tuple{"k_R", s.k_R, f.k_R_determined, s.k_R_ci}}) {
    if (det) {
      fmt::print("  {} = {:.4g} m^1/2   95% interval [{:.4g}, {:.4g}]\n", name, k, ci[0], ci[1]);
    } else {
      fmt::print("  {} not determined (at the boundary 0); 95% upper bound {} (a bound only: see the warning for the "
                 "runs that would determine it)\n",
                 name, std::isfinite(ci[1]) ? fmt::format("{:.4g} m^1/2", ci[1]) : std::string("none"));
    }
  }
  if (f.systematic_errors.estimate) {
    const SystematicErrors& e = f.systematic_errors.used;
    fmt::print("  systematic errors estimated jointly: E_d = {:.5f}{}, E_b = {:.5f}{}\n", e.c_R / e.c_L,
               f.systematic_errors.estimate->E_d_determined ? fmt::format(" +- {:.5f} (from the means and the scatter)", f.systematic_errors.estimate->E_d_se)
                                          : std::string(" (from the means; see the warning)"),
               e.E_b,
               f.systematic_errors.estimate->E_b_determined ? fmt::format(" +- {:.5f} (from the means)", f.systematic_errors.estimate->E_b_se) : "");
    for (const auto& n : f.notes) fmt::print("  note: {}\n", n);
  } else if (f.systematic_errors.source == "params") {
    fmt::print("  systematic errors from {}\n", o.params_json);
  } else {
    fmt::print("  systematic errors: none assumed (--systematic none: the robot is calibrated)\n");
  }
  fmt::print("  reference noise per pose: {:.3g} m, {:.3g} rad; model: {} order, {}\n", f.meas_sigma[0],
             f.meas_sigma[1], o.first_order ? "first" : "second", o.ml ? "ML" : "REML");
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
  for (const auto& w : f.warnings) fmt::print("  WARNING: {}\n", w);
}

/// --plot, --report, --ros2; returns what was written.
std::vector<std::string> WriteOutputs(const FitNoiseOptions& o, const api::FitNoiseResult& f) {
  std::vector<std::string> written;
  std::string svg;
  if (!o.plot.empty() || !o.report.empty()) svg = api::FitNoisePlotSvg(f);
  if (!o.plot.empty()) {
    CommandOutputs().Write(o.plot, svg);
    written.push_back(o.plot + " (plot)");
  }
  if (!o.report.empty()) {
    CommandOutputs().Write(o.report, api::FitNoiseReportHtml(f, o.inputs, svg));
    written.push_back(o.report + " (HTML report)");
  }
  if (!f.ros2) return written;
  CommandOutputs().Write(o.ros2, f.ros2->yaml);
  if (o.json.PrintText())
    fmt::print("  wrote {} (diff_drive_controller covariance at {} m/s, {} Hz)\n", o.ros2, o.covariance.speed_mps,
               o.covariance.rate_hz);
  return written;
}

// The command's steps: register files, read and fit (api::FitNoise), text,
// outputs, JSON.
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
  api::FitNoiseOptions fo;
  fo.inputs = o.inputs;
  fo.robot = {o.robot.robot_file, o.robot.wheelbase_m, o.robot.diameter_left_m, o.robot.diameter_right_m,
              o.robot.ticks_per_rev};
  fo.distance_m = o.distance_m;
  fo.meas_sigma = o.meas_sigma;
  fo.first_order = o.first_order;
  fo.ml = o.ml;
  fo.params_file = o.params_json;
  fo.systematic = o.systematic;
  fo.ros2_file = o.ros2;
  fo.controller = o.controller;
  fo.covariance = o.covariance;
  std::unique_ptr<Progress> progress;  // the fit's progress line, cleared when the fit is done
  fo.progress = [&progress](const std::string& what) {
    progress = std::make_unique<Progress>(what);
    return progress->Callback();
  };
  const api::FitNoiseResult f = api::FitNoise(fo);  // --ros2 without a usable k throws (exit 3) before any output
  progress.reset();
  if (o.json.PrintText()) {
    PrintText(o, f);
  } else {
    for (const auto& w : f.warnings) fmt::print(stderr, "fit-noise: warning: {}\n", w);
  }
  std::vector<std::string> written = WriteOutputs(o, f);
  o.json.Emit(api::ToJson(f));
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
