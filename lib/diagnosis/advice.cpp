// Reading a diagnosis for a person (see advice.hpp).
#include "diagnosis/advice.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "diagnosis/diagnose.hpp"
#include "effects/registry.hpp"

namespace umbmark::diag {

namespace {
/// Scale and unit an engineer reads a parameter in.
std::pair<double, const char*> ParamUnit(const std::string& name, const std::string& effect) {
  // An effect's own reading of its parameter (where a name means two
  // things: a slide's d and a, an asymmetry's a), else by the name.
  if (const effects::Effect* e = effects::Find(effect)) {
    const auto own = e->ParamUnit(name);
    if (own.first > 0.0) return own;
  }
  if (name == "d") return {1.0, " s^2/m"};
  if (name == "dx" || name == "dy" || name == "sigma" || name == "sigma_xy") return {1e3, " mm"};
  if (name == "kappa" || name == "sigma_theta") return {1e3, " mrad"};
  if (name == "tau" || name == "tau_sd") return {1e3, " ms"};
  if (name == "rate") return {1.0, " per metre"};
  if (name == "r") return {1.0, " per run"};
  if (name == "s" || name == "a") return {1e2, " %"};
  // Parameter errors of a given model (baseline_given.hpp).
  if (name == "error_mm") return {1.0, " mm"};
  if (name == "error_ppm") return {1.0, " ppm"};
  if (name == "relative_error") return {1e2, " %"};
  if (name == "k_L" || name == "k_R" || name == "k_L_given" || name == "k_R_given") return {1.0, " m^1/2"};
  return {1.0, ""};
}
}  // namespace

std::string FormatEffectParam(const std::string& name, double v, double se, const std::string& effect) {
  // A given model's lengths (wheelbase_m, wheel_diameter_left_m, ...): to
  // 10 micrometres, so that a millimetre's correction shows.
  if (name.size() > 2 && name.ends_with("_m")) {
    if (std::isfinite(se)) return fmt::format("{} = {:.5f} m (se {:.2g} mm)", name, v, 1e3 * se);
    return fmt::format("{} = {:.5f} m", name, v);
  }
  const auto [scale, unit] = ParamUnit(name, effect);
  if (std::isfinite(se)) return fmt::format("{} = {:.3g}{} (se {:.2g})", name, scale * v, unit, scale * se);
  return fmt::format("{} = {:.3g}{}", name, scale * v, unit);
}

std::string FormatPValue(double p) {
  if (!std::isfinite(p)) return "-";
  return p < 1e-12 ? std::string("< 1e-12") : fmt::format("{:.3g}", p);
}

std::string EvidenceInWords(double gain, double evidence, double heldout_shrink, bool noise_effect) {
  if (!std::isfinite(gain) || !std::isfinite(evidence)) return "not measured";
  const char* grade = evidence < 0.0   ? "no evidence"
                      : evidence < 1.0 ? "weak evidence"
                      : evidence < 3.0 ? "positive evidence"
                      : evidence < 5.0 ? "strong evidence"
                                       : "very strong evidence";
  std::string odds = gain > 700.0 ? "overwhelmingly"
                                  : gain > 0.0 ? fmt::format("{:.3g} times", std::exp(gain)) : std::string("not");
  if (noise_effect)
    return fmt::format("{}: runs not used to fit it are {} more probable with it ({:+.1f} nats held out; {:+.1f} "
                       "after the penalty for its parameters). It changes how widely the poses scatter, not where "
                       "they lie on average, so the likelihood is its evidence; the gap score, which weighs the mean "
                       "residuals too, closes by {:.0f}% with it on those runs",
                       grade, odds, gain, evidence, 100.0 * std::max(heldout_shrink, 0.0));
  return fmt::format("{}: on runs not used to fit it the effect closes {:.0f}% of the gap, and those runs are {} more "
                     "probable with it ({:+.1f} nats; {:+.1f} after the penalty for its parameters)",
                     grade, 100.0 * std::max(heldout_shrink, 0.0), odds, gain, evidence);
}

namespace {

/// The effects experiment `x` tells apart (Descriptor::separated_by, in
/// separated_rank order), joined as "a, b and c" (`more`: a last item
/// after them, e.g. "the wheelbase").
std::string SeparatedBy(effects::SeparatingExperiment x, const char* more = nullptr) {
  std::vector<const effects::Effect*> list;
  for (const effects::Effect* e : effects::All())
    if (e->Describe().separated_by == x) list.push_back(e);
  std::stable_sort(list.begin(), list.end(), [](const effects::Effect* a, const effects::Effect* b) {
    return a->Describe().separated_rank < b->Describe().separated_rank;
  });
  std::vector<std::string> names;
  for (const effects::Effect* e : list) names.emplace_back(e->Name());
  if (more != nullptr) names.emplace_back(more);
  std::string out;
  for (std::size_t k = 0; k < names.size(); ++k)
    out += (k == 0 ? "" : k + 1 == names.size() ? " and " : ", ") + names[k];
  return out;
}

/// The experiments and motions a campaign lacks to tell effects apart.
std::vector<std::string> MissingDesign(const CampaignData& c) {
  using X = effects::SeparatingExperiment;
  bool square = false, back_forth = false, free_path = false, pauses = false, arcs = false;
  for (const auto& e : c.experiments) {
    square |= e.kind == ExperimentKind::kSquare;
    back_forth |= e.kind == ExperimentKind::kBackAndForth;
    free_path |= e.kind == ExperimentKind::kFree;
  }
  for (const auto& p : c.pieces) {
    pauses |= p.type == PieceType::kStand;
    arcs |= p.type == PieceType::kArc;
  }
  std::vector<std::string> out;
  // Say "squares alone confuse" only of a campaign of squares alone (issue
  // 28: the sentence appeared for sessions without squares).
  const bool squares_only = square && !free_path;
  if (!back_forth)
    out.push_back(fmt::format("Add a back_and_forth experiment (drive a straight line out and back, 10 runs): driving "
                              "the same line forwards and backwards "
                              "separates {}{}.",
                              SeparatedBy(X::kBackAndForth), squares_only ? ", which squares alone confuse" : ""));
  if (!square)
    out.push_back("Add squares in both directions (UMBmark, 5+ runs each): they pin E_d and E_b, so the other "
                  "effects stand out against a well-determined baseline.");
  if (!free_path && !arcs)
    out.push_back(fmt::format("Add free paths with arcs of different radii: {} are told apart only when the robot "
                              "turns while it drives.",
                              SeparatedBy(X::kTurnsWhileDriving, "the wheelbase")));
  if (!pauses)
    out.push_back(fmt::format("Stop for 1-2 s between legs: standstills show motion while the encoders are still "
                              "({}) and average the ground truth's noise down.",
                              SeparatedBy(X::kStandstills)));
  return out;
}


/// The campaign and model numbers an effect's advice needs: E_d, E_b of
/// the explained model (fitted with the named effects) when there is an
/// explanation and no given model, else the baseline's.
effects::AdviceContext AdviceOf(const CampaignData& c, const DiagnoseSummary& s) {
  const bool explained = !s.explanation.empty() && !s.baseline.given;
  return {c.robot, explained ? s.explained_E_d : s.baseline.E_d, explained ? s.explained_E_b : s.baseline.E_b,
          s.baseline.runs, explained};
}

/// The concrete change for one named effect, in the numbers the explanation
/// fitted (the same values as its table, the JSON and the simulate command):
/// what to set on the robot, in the motion capture or in the simulation
/// (each effect's own, Effect::ConcreteChange).
std::string ConcreteChange(const ExplanationStep& step, const CampaignData& c, const DiagnoseSummary& s) {
  return effects::Of(step.effect).ConcreteChange(step.params, AdviceOf(c, s));
}

/// Where a gap statistic lies, in words: "experiment 2 (free, e2.csv),
/// circular, standstill"; the subset names "all experiments" itself when
/// the item pools them.
std::string WherePlace(const DiagnoseSummary& s, const WhereItem& w) {
  const std::string exp = w.experiment >= 0 && w.experiment < static_cast<int>(s.experiment_labels.size())
                              ? "experiment " + s.experiment_labels[w.experiment] + ", "
                              : std::string(w.subset.starts_with("all experiments") ? "" : "all experiments, ");
  return exp + w.subset;
}

}  // namespace

std::string ShrinkReferenceClause(const std::string& reference, double against_baseline) {
  if (reference == "baseline") return {};
  return fmt::format(" (measured against the baseline's mean seen with the wheel noise left once the mean effects are "
                     "fitted; {:.0f}% against the baseline itself, whose fitted wheel noise took part of them in: see "
                     "the notes)",
                     100.0 * (1.0 - against_baseline));
}

namespace {

/// A named verdict that leaves a significant remainder: what the named
/// effects close, and where to look for the rest (the explained model's
/// largest part), so the user does not expect the gap to be gone.
std::string RemainderStep(const DiagnoseSummary& s, const std::string& fixed) {
  std::string where;
  if (!s.remaining_where.empty()) {
    const WhereItem& w = s.remaining_where.front();
    where = fmt::format(" Look at it where it is largest: {}, the {} of the {} component ({:.1f} standard errors "
                        "off the explained model; umbmark evaluate --report plots those runs).",
                        WherePlace(s, w), StatKindToString(w.statistic), w.component, w.z);
  }
  // Against the shrinks' reference (docs/diagnosis.md, "The shrink's
  // reference") the share is not what the next diagnosis's own baseline
  // will show: say which G to expect.
  const std::string reference =
      s.shrink_reference == "baseline"
          ? std::string()
          : fmt::format(" (of the gap its mean shows with the wheel noise the effects leave; the next diagnosis fits "
                        "its own wheel noise, so expect its gap score near G = {:.1f}, not {:.1f})",
                        s.remaining_gap_score, s.gap_score);
  return fmt::format("Model or fix {} (fitted values in the explanation table), then diagnose again: about {:.0f}% of "
                     "the gap should be gone{}. The rest ({:.0f}% on held-out runs, G = {:.1f} against the null's "
                     "{:.1f}) is significant and no listed effect describes it.{}",
                     fixed, 100.0 * (1.0 - s.unexplained_fraction), reference, 100.0 * s.unexplained_fraction,
                     s.remaining_gap_score, s.null_quantile_alpha, where);
}

/// The steps of a named verdict: each named effect's concrete change, what
/// diagnosing again should show (the gap gone, or only the remainder
/// left), the simulate command that reproduces the runs, the symptoms.
void NamedVerdictSteps(const CampaignData& c, const DiagnoseSummary& s, const std::vector<std::string>& changes,
                       const std::vector<std::string>& symptoms, std::vector<std::string>& out) {
  out.insert(out.end(), changes.begin(), changes.end());
  const std::string fixed =
      fmt::format("{}", fmt::join(s.verdict_effects.empty() ? std::vector<std::string>{s.verdict} : s.verdict_effects,
                                  " and "));
  if (!s.remainder_significant)
    out.push_back(fmt::format("Model or fix {} (fitted values in the explanation table), then diagnose again: the "
                              "gap should be gone.", fixed));
  else
    out.push_back(RemainderStep(s, fixed));
  std::vector<std::string> specs;
  for (const auto& step : s.explanation) {
    // Parameter errors are not simulated effects (their fix is above);
    // an impossible fit is a symptom, not something to simulate.
    if (step.negligible || !step.unphysical.empty() || sim::IsParameterError(step.effect)) continue;
    std::vector<std::string> kv;
    for (const auto& [k, v] : step.params) kv.push_back(fmt::format("{}={:.4g}", k, v));
    specs.push_back(fmt::format("--effect {}:{}", sim::EffectToString(step.effect), fmt::join(kv, ",")));
  }
  if (!specs.empty())
    out.push_back(fmt::format("Check your simulation reproduces the runs: umbmark simulate {} --out DIR {} (the "
                              "fitted values, SI units), then diagnose DIR/campaign.toml: it should name the same "
                              "effects at these values (within their standard errors) and leave no significant "
                              "gap{}.",
                              c.path, fmt::join(specs, " "),
                              s.remainder_significant ? "; the simulated runs lack this remainder, which is what "
                                                        "your simulation will still miss"
                                                      : ""));
  if (!symptoms.empty())
    out.push_back("Some other candidates fitted impossible values (a symptom, not a cause): " +
                  fmt::format("{}", fmt::join(symptoms, "; ")) + ".");
}

}  // namespace

// The steps follow the verdict. For `unexplained` they start from the data
// (the largest discrepancy and where it lies), then the campaign's design
// (what is missing to separate effects), then the symptoms (impossible
// fits), then the partial explanation; for a named verdict
// NamedVerdictSteps.
std::vector<std::string> AdviseNextSteps(const CampaignData& c, const DiagnoseSummary& s) {
  std::vector<std::string> out;
  if (s.verdict == "none") {
    out.push_back(s.baseline.given ? fmt::format("Your simulation's parameters ({}) describe these runs: keep them.",
                                                 s.baseline.given->source)
                                   : "The baseline model describes these runs: simulate with its E_d, E_b and k_L, "
                                     "k_R (calibrate JSON, fit-noise).");
    return out;
  }
  // With a given model (`--baseline`): what to change in it first.
  for (const ParameterCorrection& pc : s.corrections) {
    const std::string step = "Change your simulation: " + pc.text + ".";
    if (out.empty() || out.back() != step) out.push_back(step);
  }
  std::vector<std::string> symptoms;
  for (const auto& cand : s.candidates) {
    const std::string name = sim::EffectToString(cand.effect);
    if (const std::string why = UnphysicalFit(name, cand.params, s.baseline.runs, cand.param_se); !why.empty())
      symptoms.push_back(fmt::format("{} ({})", name, why));
  }
  // For every named effect, the concrete change with the fitted numbers
  // (for `unexplained`, after the discrepancy to look at first).
  std::vector<std::string> changes;
  for (const ExplanationStep& step : s.explanation) {
    const std::string name = sim::EffectToString(step.effect);
    if (std::find(s.verdict_effects.begin(), s.verdict_effects.end(), name) == s.verdict_effects.end()) continue;
    if (std::string change = ConcreteChange(step, c, s); !change.empty()) changes.push_back(std::move(change));
  }
  if (s.verdict != "unexplained") {
    NamedVerdictSteps(c, s, changes, symptoms, out);
    return out;
  }
  // The listed effects' fixes come first when together they close at least
  // half of the gap on held-out runs (the share the verdict asks of named
  // effects): fixing them is then the larger step, and what is left is
  // looked at after; otherwise the largest discrepancy comes first.
  const bool fixes_first = !changes.empty() && 1.0 - s.unexplained_fraction >= 0.5;
  if (fixes_first) out.insert(out.end(), changes.begin(), changes.end());
  if (!s.where.empty()) {
    // What those changes leave is the explained model's largest part.
    const WhereItem& w = fixes_first && !s.remaining_where.empty() ? s.remaining_where.front() : s.where.front();
    out.push_back(fmt::format("{} {}: its {} of the {} component is {:.1f} standard errors off the "
                              "model. Plot those runs' odometry against the ground truth (umbmark evaluate --report) "
                              "and check the ground truth there (marker swaps, dropped samples, timing).",
                              fixes_first ? "Then, for what those changes leave, look at" : "Look first at",
                              WherePlace(s, w), StatKindToString(w.statistic), w.component, w.z));
  }
  if (!fixes_first) out.insert(out.end(), changes.begin(), changes.end());
  if (!symptoms.empty())
    out.push_back("These effects fitted impossible values, so the gap is something else that they try to imitate: " +
                  fmt::format("{}", fmt::join(symptoms, "; ")) + ".");
  for (auto& m : MissingDesign(c)) out.push_back(std::move(m));
  // The verdict is `unexplained`: what the listed effects close is part of
  // the answer, not the answer (the verdict's reason says why: a
  // significant gap is left, or too little is closed held out).
  if (!s.verdict_effects.empty())
  {
    const bool one = s.verdict_effects.size() == 1;
    out.push_back(fmt::format("No listed effect explains this gap (the verdict). {} {} {} {:.0f}% of "
                              "it on held-out runs, and what {} is still significant or too large: {} "
                              "(model {}, diagnose again) and look at what is left; it is "
                              "something the list does not name.",
                              one ? "The candidate" : "The candidates", fmt::join(s.verdict_effects, " + "),
                              one ? "closes" : "close", 100.0 * (1.0 - s.unexplained_fraction),
                              one ? "it leaves" : "they leave", one ? "check it" : "check them one at a time",
                              one ? "it" : "them"));
  }
  out.push_back("Check the recording itself: one clock for encoders and ground truth, the marker rigidly on the "
                "robot, the same floor and load for every run. docs/diagnosis.md lists what each effect looks like.");
  return out;
}

namespace {

/// One named effect as a plain statement with the explained model's numbers.
std::string PlainProblem(const ExplanationStep& step) { return effects::Of(step.effect).PlainProblem(step.params); }

/// A fault of the recording (marker, clocks) rather than of the robot.
bool OfTheRecording(sim::EffectKind k) { return effects::Of(k).Class() == effects::EffectClass::kMeasurement; }

}  // namespace

// Plain words first; the numbers are the explained model's (the same as the
// explanation table, the JSON and the simulate command).
std::string PlainSummary(const DiagnoseSummary& s) {
  std::vector<std::string> parts;
  if (!s.run_faults.empty()) {
    std::vector<std::string> runs;
    for (const RunFault& f : s.run_faults)
      runs.push_back(fmt::format("experiment {} run {} ({})", f.experiment + 1, f.run_id,
                                 f.statistic == "clock"    ? fmt::format("its clock is {:+.0f} ms off", 1e3 * f.tau_s)
                                 : f.statistic == "marker" ? std::string("its marker moved")
                                 : f.statistic == "event"  ? std::string("one moment of it is far off the model")
                                                           : std::string("its data scatter far more")));
    parts.push_back(fmt::format("{} faulty, not the robot: {}; fix or drop {} (left out below).",
                                s.run_faults.size() == 1 ? "One recorded run is" : "Some recorded runs are",
                                fmt::join(runs, ", "), s.run_faults.size() == 1 ? "it" : "them"));
  }
  std::vector<std::string> robot, recording;
  for (const ExplanationStep& st : s.explanation) {
    const std::string name = sim::EffectToString(st.effect);
    if (std::find(s.verdict_effects.begin(), s.verdict_effects.end(), name) == s.verdict_effects.end()) continue;
    if (sim::IsParameterError(st.effect)) continue;  // the corrections below say it
    (OfTheRecording(st.effect) ? recording : robot).push_back(PlainProblem(st));
  }
  for (const ParameterCorrection& pc : s.corrections) robot.push_back("your simulation: " + pc.text);
  const bool unexplained = s.verdict == "unexplained";
  if (s.verdict == "none") {
    parts.push_back(s.baseline.given ? "Nothing that matters is wrong: your simulation describes these runs within "
                                       "their noise."
                                     : "Nothing that matters is wrong: the calibrated model describes these runs "
                                       "within their noise.");
  } else {
    if (unexplained)
      parts.push_back("The runs differ from the model in a way no listed effect explains" +
                      std::string(robot.empty() && recording.empty()
                                      ? "."
                                      : fmt::format(" (the effects below explain {:.0f}% of it).",
                                                    100.0 * (1.0 - s.unexplained_fraction))));
    if (!robot.empty())
      parts.push_back(fmt::format("{}: {}.", unexplained ? "Partly, the robot" : "The robot", fmt::join(robot, "; ")));
    if (!recording.empty())
      parts.push_back(fmt::format("{}: {}.", unexplained ? "Partly, the recording" : "The recording",
                                  fmt::join(recording, "; ")));
    if (!unexplained && s.remainder_significant)
      parts.push_back(fmt::format("{} {:.0f}% of the gap; the rest is something no listed effect describes.",
                                  s.verdict_effects.size() == 1 ? "This explains" : "These explain",
                                  100.0 * (1.0 - s.unexplained_fraction)));
  }
  if (!s.next_steps.empty()) parts.push_back("What to do first: " + s.next_steps.front());
  return fmt::format("{}", fmt::join(parts, " "));
}

}  // namespace umbmark::diag
