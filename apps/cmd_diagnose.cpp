// `umbmark diagnose MANIFEST.toml`: where a campaign leaves the baseline
// model (E_d, E_b, k_L, k_R), which contract effect causes the gap, and how
// far it shrinks once that effect is modelled (lib/diagnosis/diagnose.hpp).
// Readable report on stdout, contract JSON with --json, gap bars with --plot.
// The computation is the library's api::Diagnose (lib/api/diagnose.hpp):
// this file binds the flags to its options, prints and draws.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "api/diagnose.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "core/errors.hpp"
#include "api/diagnose_report.hpp"
#include "progress.hpp"

namespace umbmark::cli {

namespace {

/// The command line's options: the library's, its output files and the gate.
struct DiagnoseFlags {
  api::DiagnoseOptions o;
  std::string plot;
  std::string report;
  bool quality_gate = false;
  JsonFlag json;
};

int RunDiagnose(DiagnoseFlags f) {
  if (std::string err = f.o.Check(); !err.empty()) throw InvalidOptions(err);
  io::OutputSet& outs = CommandOutputs();
  RegisterInputs(f.o.baseline.empty() ? std::vector<std::string>{f.o.manifest}
                                      : std::vector<std::string>{f.o.manifest, f.o.baseline});
  outs.AddOutput("--json", f.json.path);
  outs.AddOutput("--plot", f.plot);
  outs.AddOutput("--report", f.report);
  outs.Check();
  const api::DiagnoseResult r = [&] {
    Progress progress(fmt::format("diagnosing {} ({} null simulations)", f.o.manifest, f.o.diag.null_simulations));
    f.o.progress = progress.Callback();
    return api::Diagnose(f.o);
  }();
  if (f.json.PrintText()) {
    fmt::print("{}", diag::DiagnoseReport(r.summary));
    for (const auto& w : r.data_warnings) fmt::print("WARNING: {}\n", w);
  } else {
    for (const auto& w : r.data_warnings) fmt::print(stderr, "warning: {}\n", w);
  }
  const nlohmann::json j = api::ToJson(r);
  std::vector<std::string> written;
  if (!f.plot.empty()) {
    outs.Write(f.plot, api::DiagnosePlotsSvg(j));
    written.push_back(f.plot + " (plot)");
  }
  if (!f.report.empty()) {
    outs.Write(f.report, api::DiagnoseReportHtml(j, f.o.manifest));
    written.push_back(f.report + " (HTML report)");
  }
  f.json.EmitAndListOutputs(j, written);
  if (f.quality_gate && r.summary.verdict == "unexplained") {
    throw QualityGateError("the campaign leaves the model and no known effect explains the gap");
  }
  return 0;
}

}  // namespace

Command SetupDiagnose(CLI::App& parent) {
  auto opts = std::make_shared<DiagnoseFlags>();
  auto* app = parent.add_subcommand("diagnose", "Sim-to-real gap: where it lies, which effect causes it, how far it shrinks");
  app->add_option("MANIFEST", opts->o.manifest, "Campaign manifest (TOML)")->required();
  auto& d = opts->o.diag;
  app->add_option("--null-sims", d.null_simulations, "Simulated baseline campaigns for the p-value (default 500)")
      ->check(NumberIn(20, 1000000));
  app->add_option("--alpha", d.alpha, "False-alarm rate of the gap test (default 0.01)")->check(NumberIn(1e-6, 0.5));
  app->add_option("--min-heldout-shrink", d.min_heldout_shrink,
                  "Held-out shrink a winning effect needs (default 0.5)")
      ->check(NumberIn(0.01, 1.0));
  app->add_option("--penalty", d.complexity_penalty_nats, "Held-out nats an effect must gain per parameter (default 2)")
      ->check(NonNegative());
  app->add_option("--decisive", d.decisive_nats,
                  "Held-out nats an effect must earn given the explanation's other effects, after its penalty, to "
                  "be named in the verdict (default 4.61 = ln 100: a likelihood ratio of 100, decisive on "
                  "Jeffreys' scale)")
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
  app->add_flag_callback(
      "--fit-ground-truth-noise", [opts] { opts->o.diag.baseline_fit.ground_truth = diag::GroundTruthNoiseSource::kFitted; },
      "Fit the ground truth's noise with the wheel noise on the pieces (before issue 28; an unmodelled effect can "
      "widen it) instead of taking the scatter inside the standstills (default), when the manifest states none");
  CLI::Option* hold = app->add_flag_callback(
      "--hold-wheel-noise", [opts] { opts->o.diag.baseline_fit.wheel = diag::WheelNoiseSource::kRepeats; },
      "Hold the wheel noise k_L, k_R at the scatter of repeated runs about their own mean, where the design supports "
      "it (a mean effect cannot widen it; each candidate re-measures it there jointly with its own run-to-run "
      "variance), instead of fitting it jointly with E_d, E_b on the pieces (the default)");
  app->add_flag_callback(
      "--fit-wheel-noise", [opts] { opts->o.diag.baseline_fit.wheel = diag::WheelNoiseSource::kFitted; },
      "Fit the wheel noise k_L, k_R jointly with E_d, E_b on the pieces (the default; a mean effect the baseline "
      "leaves out can widen it) instead of holding it at the scatter of repeated runs; that scatter is still "
      "measured, with a warning when the two disagree")
      ->excludes(hold);
  app->add_flag("--monotone-shrink,!--no-monotone-shrink", d.keep_heldout_shrink,
                "A step of the explanation may not lower the cumulative held-out shrink (default: off)");
  app->add_option("--max-effects", d.max_explanation_effects, "Most effects in the stepwise explanation (default 4)")
      ->check(CLI::Range(1, 12));
  app->add_option("--seed", d.seed, "Seed of the null simulations (default 1)")->check(SeedValidator());
  app->add_option("--threads", d.threads, "Threads (default 2)")->check(NumberIn(1, 256));
  app->add_option("--where", d.where_top, "Discrepancies listed under 'where' (default 12)")->check(NonNegative());
  app->add_option("--effects", opts->o.effects,
                  "Effects to try, comma-separated (default: the contract's fourteen; with --baseline also its "
                  "parameter errors)")
      ->delimiter(',');
  app->add_option("--plot", opts->plot,
                  "SVG: located discrepancies against the model's 95% band, shrink per candidate and of the explanation");
  app->add_option("--report", opts->report, "Write a self-contained HTML report (verdict, next steps, tables, plots)");
  app->add_flag("--fail-unexplained", opts->quality_gate, "Exit 3 when the verdict is 'unexplained'");
  app->add_option("--baseline", opts->o.baseline,
                  "Compare the runs with your simulation's parameters (a `calibrate` JSON: refined.parameters if "
                  "present) instead of a model fitted to them; also names wheelbase_error and diameter_ratio_error");
  app->add_flag("--baseline-other-robot", opts->o.baseline_other_robot,
                "Accept a --baseline from another robot (parameters more than 10 % from the campaign's, or "
                "calibrated from runs recorded with another robot file); refused without it")
      ->needs(app->get_option("--baseline"));
  app->add_option("--kl", opts->o.k_L,
                  "With --baseline: your simulation's left wheel noise k_L [m^1/2] (with --kr; also names "
                  "wheel_noise_error; without them the noise is fitted)");
  app->add_option("--kr", opts->o.k_R, "With --baseline: your simulation's right wheel noise k_R [m^1/2] (with --kl)");
  opts->json.Bind(*app);
  return {app, [opts] { return RunDiagnose(*opts); }};
}

}  // namespace umbmark::cli
