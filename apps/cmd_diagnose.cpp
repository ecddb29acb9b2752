// `umbmark diagnose MANIFEST.toml`: where a campaign leaves the baseline
// model (E_d, E_b, k_L, k_R), which contract effect causes the gap, and how
// far it shrinks once that effect is modelled (lib/diagnosis/diagnose.hpp).
// Readable report on stdout, contract JSON with --json, gap bars with --plot.
#include <algorithm>
#include <cmath>
#include <memory>
#include <variant>
#include <optional>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "diagnosis/design_check.hpp"
#include "formats/manifest.hpp"
#include "api/diagnose_report.hpp"
#include "progress.hpp"
#include "common.hpp"
#include "core/errors.hpp"
#include "evaluation/data_warnings.hpp"
#include "diagnosis/pieces.hpp"
#include "diagnosis/diagnose.hpp"
#include "output/atomic_write.hpp"
#include "formats/file_text.hpp"
#include "formats/params_json.hpp"
#include "report/svg_plot.hpp"

namespace umbmark::cli {

namespace {

struct DiagnoseCliOptions {
  std::string manifest;
  diag::DiagnoseOptions diag;
  std::vector<std::string> effects;
  std::string plot;
  std::string report;
  bool quality_gate = false;
  std::string baseline;  ///< --baseline CAL.json
  bool baseline_other_robot = false;  ///< --baseline-other-robot: take a baseline from another robot
  std::optional<double> k_L, k_R;
  JsonFlag json;
};

/// A --baseline whose wheelbase or a wheel diameter differs from the
/// campaign's recorded one by more than this (relative) is another robot's
/// (UMBmark corrections of a real robot are a few per cent at most).
constexpr double kOtherRobotRelative = 0.10;

/// Refuses (InputError, exit 1) a --baseline that belongs to another robot
/// than the campaign's, unless --baseline-other-robot: its parameters lie
/// more than kOtherRobotRelative from the campaign's recorded ones, or its
/// own `recorded_parameters` (the robot file it was calibrated from) differ
/// from the campaign's while its result is not the campaign's robot either
/// (a second pass on a compensated robot records the corrected parameters:
/// accepted).
void CheckBaselineRobot(const std::string& path, const RobotParams& given, const RobotParams& campaign) {
  const auto rel = [](double a, double b) { return std::abs(a / b - 1.0); };
  const auto largest = [&](const RobotParams& a) {
    return std::max({rel(a.wheelbase_m, campaign.wheelbase_m), rel(a.wheel_diameter_left_m, campaign.wheel_diameter_left_m),
                     rel(a.wheel_diameter_right_m, campaign.wheel_diameter_right_m)});
  };
  const auto describe = [](const RobotParams& p) {
    return fmt::format("wheelbase {:.6g} m, wheel diameters {:.6g} / {:.6g} m", p.wheelbase_m, p.wheel_diameter_left_m,
                       p.wheel_diameter_right_m);
  };
  const std::string hint = "compare a robot with its own calibration or simulation, or give --baseline-other-robot "
                           "to compare with this one on purpose";
  if (largest(given) > kOtherRobotRelative) {
    throw InputError(path, fmt::format("--baseline is another robot's: its parameters ({}) differ by {:.1f} % from "
                                       "the campaign's recorded robot ({}), more than the {:.0f} % a calibration "
                                       "corrects; {}",
                                       describe(given), 100.0 * largest(given), describe(campaign),
                                       100.0 * kOtherRobotRelative, hint));
  }
  nlohmann::json j = io::ParseJsonDocument(io::ReadWholeFile(path), path);
  if (j.is_object() && j.contains("results") && j["results"].is_array() && j["results"].size() == 1) j = j["results"][0];
  if (!j.is_object() || !j.contains("recorded_parameters")) return;  // a hand-written simulation model
  const nlohmann::json& r = j["recorded_parameters"];
  RobotParams recorded = campaign;
  for (auto [key, field] : {std::pair{"wheelbase_m", &recorded.wheelbase_m},
                            std::pair{"wheel_diameter_left_m", &recorded.wheel_diameter_left_m},
                            std::pair{"wheel_diameter_right_m", &recorded.wheel_diameter_right_m}}) {
    if (r.is_object() && r.contains(key) && r[key].is_number()) *field = r[key].get<double>();
  }
  constexpr double kSame = 1e-6;
  if (largest(recorded) <= kSame || largest(given) <= kSame) return;
  throw InputError(path, fmt::format("--baseline was calibrated from another robot's runs: its recorded_parameters "
                                     "({}) are not the campaign's recorded robot ({}); {}",
                                     describe(recorded), describe(campaign), hint));
}

/// --kl / --kr: both or neither, finite, >= 0, not both 0; only with --baseline.
void CheckGivenNoise(const DiagnoseCliOptions& o) {
  if ((o.k_L || o.k_R) && o.baseline.empty())
    throw InvalidOptions("--kl/--kr give the wheel noise of a model given by --baseline CAL.json; without "
                         "--baseline the noise is fitted to the runs");
  if (o.k_L.has_value() != o.k_R.has_value())
    throw InvalidOptions(fmt::format("{} given without {}: give both wheels' noise k_L and k_R [m^1/2] (or neither, "
                                     "and it is fitted)",
                                     o.k_L ? "--kl" : "--kr", o.k_L ? "--kr" : "--kl"));
  for (const auto& [flag, v] : {std::pair{"--kl", o.k_L}, std::pair{"--kr", o.k_R}})
    if (v && !(std::isfinite(*v) && *v >= 0.0))
      throw InvalidOptions(fmt::format("{} = {} must be a finite wheel noise >= 0 [m^1/2]", flag, *v));
  if (o.k_L && *o.k_L == 0.0 && *o.k_R == 0.0)
    throw InvalidOptions("--kl and --kr are both 0: a model without wheel noise cannot be compared with real runs");
}

int RunDiagnose(DiagnoseCliOptions o) {
  for (const auto& name : o.effects) {
    const auto k = sim::EffectFromString(name);
    if (!k) throw InvalidOptions(fmt::format("--effects: unknown effect '{}'", name));
    o.diag.effects.push_back(*k);
  }
  CheckGivenNoise(o);
  io::OutputSet& outs = CommandOutputs();
  RegisterInputs(o.baseline.empty() ? std::vector<std::string>{o.manifest}
                                    : std::vector<std::string>{o.manifest, o.baseline});
  outs.AddOutput("--json", o.json.path);
  outs.AddOutput("--plot", o.plot);
  outs.AddOutput("--report", o.report);
  outs.Check();
  // A design that cannot determine the baseline is refused before fitting.
  if (const std::string why = diag::CampaignDesignProblem(io::ReadManifest(o.manifest)); !why.empty()) {
    throw InputError(o.manifest, why);
  }
  const diag::CampaignData campaign = diag::LoadCampaign(o.manifest, o.diag.pieces);
  // Degenerate data (evaluation/data_warnings.hpp), per file: trajectories
  // and return errors.
  std::vector<std::string> warnings;
  for (const auto& file : campaign.files) {
    if (const auto* t = std::get_if<TrajectoryData>(&file)) {
      TrajectoryDataCheck check(campaign.robot);
      for (const auto& run : t->runs) check.Add(run);
      for (auto& w : check.Warnings(t->path)) warnings.push_back(std::move(w));
    } else if (const auto* e = std::get_if<EndpointData>(&file)) {
      EndpointDataCheck check;
      for (const auto& run : e->runs) check.Add(run);
      for (auto& w : check.Warnings(e->path)) warnings.push_back(std::move(w));
    }
  }
  if (!o.baseline.empty()) {
    diag::GivenModel g;
    g.params = io::ReadParamsJson(o.baseline, campaign.robot);
    if (!o.baseline_other_robot) CheckBaselineRobot(o.baseline, g.params, campaign.robot);
    g.source = o.baseline;
    g.noise_given = o.k_L.has_value();
    g.k_L = o.k_L.value_or(0.0);
    g.k_R = o.k_R.value_or(0.0);
    o.diag.given = g;
  }
  const diag::DiagnoseSummary s = [&] {
    Progress progress(fmt::format("diagnosing {} ({} null simulations)", o.manifest, o.diag.null_simulations));
    diag::DiagnoseOptions d = o.diag;
    d.progress = progress.Callback();
    return diag::Diagnose(campaign, d);
  }();
  if (o.json.PrintText()) {
    fmt::print("{}", diag::DiagnoseReport(s));
    for (const auto& w : warnings) fmt::print("WARNING: {}\n", w);
  } else {
    for (const auto& w : warnings) fmt::print(stderr, "warning: {}\n", w);
  }
  nlohmann::json j = diag::DiagnoseToJson(s);
  if (!warnings.empty()) {
    nlohmann::json all = j.value("warnings", nlohmann::json::array());
    for (const auto& w : warnings) all.push_back(w);
    j["warnings"] = all;
  }
  j["manifest"] = o.manifest;
  std::vector<std::string> written;
  if (!o.plot.empty()) {
    outs.Write(o.plot, api::DiagnosePlotsSvg(j));
    written.push_back(o.plot + " (plot)");
  }
  if (!o.report.empty()) {
    outs.Write(o.report, api::DiagnoseReportHtml(j, o.manifest));
    written.push_back(o.report + " (HTML report)");
  }
  o.json.EmitAndListOutputs(j, written);
  if (o.quality_gate && s.verdict == "unexplained") {
    throw QualityGateError("the campaign leaves the model and no known effect explains the gap");
  }
  return 0;
}

}  // namespace

Command SetupDiagnose(CLI::App& parent) {
  auto opts = std::make_shared<DiagnoseCliOptions>();
  auto* app = parent.add_subcommand("diagnose", "Sim-to-real gap: where it lies, which effect causes it, how far it shrinks");
  app->add_option("MANIFEST", opts->manifest, "Campaign manifest (TOML)")->required();
  auto& d = opts->diag;
  app->add_option("--null-sims", d.null_simulations, "Simulated baseline campaigns for the p-value (default 500)")
      ->check(NumberIn(20, 1000000));
  app->add_option("--alpha", d.alpha, "False-alarm rate of the gap test (default 0.01)")->check(NumberIn(1e-6, 0.5));
  app->add_option("--min-heldout-shrink", d.min_heldout_shrink,
                  "Held-out shrink a winning effect needs (default 0.5)")
      ->check(NumberIn(0.01, 1.0));
  app->add_option("--penalty", d.complexity_penalty_nats, "Held-out nats an effect must gain per parameter (default 2)")
      ->check(NonNegative());
  app->add_option("--folds", d.pieces.folds, "Cross-validation folds over runs (default 5)")->check(NumberIn(2, 100));
  app->add_option("--piece-length", d.pieces.max_piece_length_m,
                  "Longest piece of a leg or arc compared with the model [m] (default 1; 0.01 to 1000)")
      ->check(NumberIn(0.01, 1000.0));
  app->add_flag("!--no-likelihood-tests", d.likelihood_tests,
               "Judge the gap by the gap score alone (default: combined with the candidates' likelihood-ratio tests)");
  app->add_flag("!--no-standstill-averaging", d.pieces.average_standstills,
                "Measure motions from/to single ground-truth samples (default: the adjacent standstills' mean pose)");
  app->add_option("--negligible", d.negligible,
                  "Practical significance: effects that move the predicted pose over a run by less than this "
                  "fraction of the noise of one piece (<= 1 m or a spot turn), and noise effects that widen the "
                  "pose spread of the pieces they act on (median per piece type, the type widened most) by less "
                  "than this fraction, are negligible, never the verdict (default 0.25)")
      ->check(CLI::NonNegativeNumber);
  app->add_option("--max-effects", d.max_explanation_effects, "Most effects in the stepwise explanation (default 4)")
      ->check(CLI::Range(1, 12));
  app->add_option("--seed", d.seed, "Seed of the null simulations (default 1)")->check(SeedValidator());
  app->add_option("--threads", d.threads, "Threads (default 2)")->check(NumberIn(1, 256));
  app->add_option("--where", d.where_top, "Discrepancies listed under 'where' (default 12)")->check(NonNegative());
  app->add_option("--effects", opts->effects,
                  "Effects to try, comma-separated (default: the contract's fourteen; with --baseline also its "
                  "parameter errors)")
      ->delimiter(',');
  app->add_option("--plot", opts->plot,
                  "SVG: located discrepancies against the model's 95% band, shrink per candidate and of the explanation");
  app->add_option("--report", opts->report, "Write a self-contained HTML report (verdict, next steps, tables, plots)");
  app->add_flag("--fail-unexplained", opts->quality_gate, "Exit 3 when the verdict is 'unexplained'");
  app->add_option("--baseline", opts->baseline,
                  "Compare the runs with your simulation's parameters (a `calibrate` JSON: refined.parameters if "
                  "present) instead of a model fitted to them; also names wheelbase_error and diameter_ratio_error");
  app->add_flag("--baseline-other-robot", opts->baseline_other_robot,
                "Accept a --baseline from another robot (parameters more than 10 % from the campaign's, or "
                "calibrated from runs recorded with another robot file); refused without it")
      ->needs(app->get_option("--baseline"));
  app->add_option("--kl", opts->k_L,
                  "With --baseline: your simulation's left wheel noise k_L [m^1/2] (with --kr; also names "
                  "wheel_noise_error; without them the noise is fitted)");
  app->add_option("--kr", opts->k_R, "With --baseline: your simulation's right wheel noise k_R [m^1/2] (with --kl)");
  opts->json.Bind(*app);
  return {app, [opts] { return RunDiagnose(*opts); }};
}

}  // namespace umbmark::cli
