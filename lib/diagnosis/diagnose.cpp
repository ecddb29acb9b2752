// The diagnosis driver: a short list of named stages (see diagnose.hpp),
// each in its own file, timed.
#include "diagnosis/diagnose.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "calibration/umbmark.hpp"
#include "core/errors.hpp"
#include "diagnosis/campaign_scale.hpp"
#include "diagnosis/advice.hpp"
#include "diagnosis/baseline.hpp"
#include "diagnosis/candidates.hpp"
#include "diagnosis/cross_validation.hpp"
#include "diagnosis/design_check.hpp"
#include "diagnosis/explanation.hpp"
#include "diagnosis/mechanism_spread.hpp"
#include "diagnosis/mean_fit.hpp"
#include "diagnosis/null_distribution.hpp"
#include "diagnosis/return_check.hpp"
#include "diagnosis/stop_model.hpp"
#include "diagnosis/verdict.hpp"
#include "diagnosis/where.hpp"
#include "effects/registry.hpp"
#include "planning/advice.hpp"

namespace umbmark::diag {

std::string DiagnoseOptions::Check() const {
  if (null_simulations < 20) return fmt::format("null_simulations = {} must be >= 20", null_simulations);
  if (!(alpha > 0.0 && alpha < 0.5)) return fmt::format("alpha = {} must be in (0, 0.5)", alpha);
  if (!(full_shrink >= min_heldout_shrink && full_shrink <= 1.0))
    return fmt::format("full_shrink = {} must be in [min_heldout_shrink, 1]", full_shrink);
  if (!(min_heldout_shrink > 0.0 && min_heldout_shrink <= 1.0))
    return fmt::format("min_heldout_shrink = {} must be in (0, 1]", min_heldout_shrink);
  if (!(complexity_penalty_nats >= 0.0))
    return fmt::format("complexity_penalty_nats = {} must be >= 0", complexity_penalty_nats);
  if (!(decisive_nats >= 0.0)) return fmt::format("decisive_nats = {} must be >= 0", decisive_nats);
  if (threads < 1) return fmt::format("threads = {} must be >= 1", threads);
  if (!(negligible >= 0.0)) return fmt::format("negligible = {} must be >= 0", negligible);
  if (max_explanation_effects < 1)
    return fmt::format("max_explanation_effects = {} must be >= 1", max_explanation_effects);
  if (where_top < 0) return fmt::format("where_top = {} must be >= 0", where_top);
  if (auto e = baseline_fit.Check(); !e.empty()) return "baseline_fit." + e;
  if (given) {
    if (auto e = given->Check(); !e.empty()) return "given model: " + e;
  }
  for (sim::EffectKind k : effects) {
    if (!sim::IsParameterError(k)) continue;
    if (!given)
      return fmt::format("effect {} is a parameter error of a given model: a candidate only with --baseline CAL.json",
                         sim::EffectToString(k));
    if (NoiseTermOf(k) == effects::NoiseTerm::kWheelNoise && !given->noise_given)
      return fmt::format("effect {} needs the given model's wheel noise (--kl, --kr)", sim::EffectToString(k));
  }
  if (auto e = pieces.Check(); !e.empty()) return "pieces: " + e;
  if (auto e = run_faults.Check(); !e.empty()) return "run_faults: " + e;
  if (!(gap.threshold_se >= 0.0)) return fmt::format("gap.threshold_se = {} must be >= 0", gap.threshold_se);
  return {};
}

namespace {

using Clock = std::chrono::steady_clock;

/// Wall-clock time of each stage, in order.
class StageTimer {
 public:
  StageTimer() : last_(Clock::now()), start_(last_) {}
  void Lap(const char* stage) {
    const auto now = Clock::now();
    timings_.emplace_back(stage, std::chrono::duration<double>(now - last_).count());
    last_ = now;
  }
  std::vector<std::pair<std::string, double>> Finish() {
    timings_.emplace_back("total", std::chrono::duration<double>(Clock::now() - start_).count());
    return timings_;
  }

 private:
  Clock::time_point last_, start_;
  std::vector<std::pair<std::string, double>> timings_;
};

BaselineSummary Summarise(const CampaignData& c, const BaselineStart& start, const BaselineFit& b, ReturnCheck rc) {
  // (rc by value: its vectors move into the summary)
  BaselineSummary bs;
  bs.E_d = b.p[kParamEd];
  bs.E_b = b.p[kParamEb];
  bs.k_L = std::sqrt(b.noise.kL2);
  bs.k_R = std::sqrt(b.noise.kR2);
  bs.sigma_xy_m = std::sqrt(b.noise.sxy2);
  bs.sigma_theta_rad = std::sqrt(b.noise.sth2);
  bs.ground_truth_estimated = !b.ground_truth_known;
  bs.ground_truth_source = b.ground_truth_source;
  bs.standstill = b.standstill;
  bs.pieces_sigma_xy_m = b.pieces_sigma_xy_m;
  bs.pieces_sigma_theta_rad = b.pieces_sigma_theta_rad;
  bs.wheel_noise_source = b.wheel_noise_source;
  bs.repeat = b.repeat;
  bs.pieces_k_L = b.pieces_k_L;
  bs.pieces_k_R = b.pieces_k_R;
  bs.start = start.description;
  bs.pieces = static_cast<int>(c.pieces.size());
  bs.runs = static_cast<int>(c.runs.size());
  bs.returns = std::move(rc.returns);
  bs.growth = std::move(rc.growth);
  bs.return_fit = rc.return_fit;
  bs.return_k_L = rc.return_k_L;
  bs.return_k_R = rc.return_k_R;
  bs.return_k_L_ci = rc.return_k_L_ci;
  bs.return_k_R_ci = rc.return_k_R_ci;
  bs.return_fit_note = std::move(rc.return_fit_note);
  return bs;
}

/// Whether the verdict names `effect` (out.verdict_effects).
bool Named(const DiagnoseSummary& out, sim::EffectKind effect) {
  const std::string name = sim::EffectToString(effect);
  return std::find(out.verdict_effects.begin(), out.verdict_effects.end(), name) != out.verdict_effects.end();
}

/// With a given model: parameters in the user's terms (baseline_given.hpp)
/// and the corrections for every parameter error the verdict names.
void DescribeGivenModel(const CampaignData& c, const GivenModel& given, DiagnoseSummary& out) {
  for (Candidate& cd : out.candidates) {
    cd.params = DescribeGivenParams(cd.effect, cd.params, c.robot, given);
    cd.param_se = DescribeGivenParamErrors(cd.effect, cd.param_se, c.robot, given);
  }
  for (ExplanationStep& s : out.explanation) {
    s.params = DescribeGivenParams(s.effect, s.params, c.robot, given);
    if (!Named(out, s.effect) || !sim::IsParameterError(s.effect)) continue;
    for (ParameterCorrection& pc : Corrections(s.effect, s.params, given, out.negligible_threshold)) out.corrections.push_back(std::move(pc));
  }
}

/// The baseline under the stop reading (stop_model.hpp) the runs support:
/// both readings are fitted when the campaign has joint stops with encoder
/// counts, and the one with the higher likelihood is kept (same free
/// parameters in both). `model` refers to `*body` or to the recorded
/// campaign; a StopChoice is not copied.
struct StopChoice {
  std::unique_ptr<CampaignData> body;  ///< the body reading, when chosen
  std::unique_ptr<MeanModel> model;
  BaselineFit base;
  bool compared = false;
  double loglik_margin = 0.0;  ///< chosen minus the other [nats]
};

BaselineFit FitStart(const CampaignData& c, const MeanModel& model, const BaselineStart& start,
                     const DiagnoseOptions& options) {
  return options.given ? FitGivenBaseline(c, model, *options.given, options.baseline_fit)
                       : FitBaseline(c, model, start, options.baseline_fit);
}

StopChoice ChooseStopModel(const CampaignData& recorded, const BaselineStart& start, const DiagnoseOptions& options) {
  StopChoice out;
  out.model = std::make_unique<MeanModel>(recorded);
  out.base = FitStart(recorded, *out.model, start, options);
  if (!HasJointStops(recorded)) return out;
  auto body = std::make_unique<CampaignData>(WithBodyStops(recorded));
  auto body_model = std::make_unique<MeanModel>(*body);
  BaselineFit body_base = FitStart(*body, *body_model, start, options);
  const double ll_edge = TotalLogLik(recorded, out.base.bases, out.base.eps, out.base.noise);
  const double ll_body = TotalLogLik(*body, body_base.bases, body_base.eps, body_base.noise);
  out.compared = std::isfinite(ll_edge) && std::isfinite(ll_body);
  if (out.compared && ll_body > ll_edge) {
    out.body = std::move(body);
    out.model = std::move(body_model);
    out.base = std::move(body_base);
  }
  out.loglik_margin = out.compared ? std::abs(ll_body - ll_edge) : 0.0;
  return out;
}

/// The explanation's steps in the order the verdict names them: first the
/// effect that earns most held-out evidence given all the others
/// (ExplanationStep::earned_given_others_nats), the one whose absence would
/// reopen most of the gap. The steps' own order is the greedy path, where a
/// noise effect that imitated part of a mean effect may come first and be
/// needed far less once that effect is in.
std::vector<const ExplanationStep*> ByEarnings(const Explanation& ex) {
  std::vector<const ExplanationStep*> order;
  for (const ExplanationStep& s : ex.steps) order.push_back(&s);
  std::stable_sort(order.begin(), order.end(), [](const ExplanationStep* x, const ExplanationStep* y) {
    return x->earned_given_others_nats > y->earned_given_others_nats;
  });
  return order;
}

/// The effects the verdict lists but does not name: negligible ones, ones
/// whose evidence given the others is not decisive (`weak`, with their
/// nats), ones fitted outside their physical range within its tolerance
/// (`outside`, with why) and fits at impossible values (symptoms).
std::string NotNamedText(const std::vector<std::string>& negligible, const std::vector<std::string>& weak,
                         const std::vector<std::string>& outside, const std::vector<std::string>& spreads,
                         const std::vector<std::string>& impossible, double level, double decisive) {
  std::string text = negligible.empty()
                         ? std::string()
                         : fmt::format("; negligible in practice (size below {:.2g} x the noise of one piece): {}",
                                       level, fmt::join(negligible, ", "));
  if (!weak.empty())
    text += fmt::format("; not decisive given the other effects (a held-out likelihood ratio below {:.0f}, "
                        "{:.2f} nats, after the penalty for its parameters): {}",
                        std::exp(decisive), decisive, fmt::join(weak, ", "));
  if (!outside.empty())
    text += fmt::format("; fitted outside the physical range, though within its standard errors of it (no cause a "
                        "robot can have; not named): {}",
                        fmt::join(outside, "; "));
  if (!spreads.empty())
    text += fmt::format("; the named mechanisms' scatter about their one value (a spread no larger than the mean it "
                        "varies about, or than the mechanism's own scatter, where it lies; not named): {}",
                        fmt::join(spreads, "; "));
  if (!impossible.empty())
    text += fmt::format("; fitted at impossible values (a symptom, not named, never a step): {}",
                        fmt::join(impossible, ", "));
  return text;
}

/// What a named explanation leaves: no significant gap, a misfit of its
/// shape (under 1 - full_shrink of the held-out gap, against the shrinks'
/// reference and the baseline: `excused` is the smaller shrink), or a
/// remainder (its share of the reference's held-out gap, and of the
/// baseline's when that is larger).
std::string WhatIsLeft(bool gap_left, const char* leave, double heldout, double excused, double gap_after,
                       double quantile, double full_shrink) {
  if (!gap_left) return fmt::format("{} no significant gap (G = {:.1f} <= {:.1f})", leave, gap_after, quantile);
  if (excused >= full_shrink)
    return fmt::format("{} G = {:.1f} > {:.1f}, less than {:.0f}% of the held-out gap (a misfit of the effects' shape)",
                       leave, gap_after, quantile, 100.0 * (1.0 - full_shrink));
  const std::string share =
      excused < heldout ? fmt::format("{:.0f}% of the held-out gap ({:.0f}% of the baseline's, whose fitted wheel noise "
                                      "took part of the effects in)",
                                      100.0 * (1.0 - heldout), 100.0 * std::min(1.0, 1.0 - excused))
                        : fmt::format("{:.0f}% of the held-out gap", 100.0 * (1.0 - heldout));
  return fmt::format("{} G = {:.1f} > {:.1f}: a significant remainder, {}, that no listed effect describes (where it "
                     "lies: below)",
                     leave, gap_after, quantile, share);
}

/// Why the effects of an `unexplained` verdict are not enough (`one`: a
/// single effect, the verbs in the singular).
std::string WhyNotEnough(bool one, bool gap_left, bool systematic, double gap_after, double quantile,
                         double mean_share, double min_heldout_shrink) {
  const char* leave = one ? "leaves" : "leave";
  if (!gap_left) return fmt::format("{} less than {:.0f}% of it", one ? "closes" : "close", 100.0 * min_heldout_shrink);
  if (systematic)
    return fmt::format("{} a significant gap (G = {:.1f} > {:.1f}) that lies mostly in the runs' means ({:.0f}% "
                       "of it in mean and trend statistics: something systematic no listed effect describes)",
                       leave, gap_after, quantile, 100.0 * mean_share);
  return fmt::format("{} a significant gap (G = {:.1f} > {:.1f})", leave, gap_after, quantile);
}

/// The verdict from the explanation (docs/diagnosis.md, "The verdict's
/// rule"): its effects that are neither negligible, nor short of decisive
/// evidence given the others (ExplanationStep::not_decisive), nor fitted
/// outside their physical range (ExplanationStep::outside_range), nor a
/// named mechanism's spread (ExplanationStep::spread_of_named), nor
/// at impossible values (advice.hpp UnphysicalFit, e.g. a negative turn
/// scrub: a symptom of something else, never a cause) are named when no impossible fit
/// outranked its first step (Explanation::symptom_first) and either the
/// explanation closes the larger part (min_heldout_shrink) of the gap the
/// score found on held-out runs and what it leaves lies mostly outside
/// the runs' means (a significant remainder is reported beside them:
/// remainder_significant, remainder_mean_share), or it leaves no significant gap
/// (G at or below the null's 1 - alpha quantile, or full_shrink of the
/// held-out gap closed; when the score found the gap, at least
/// min_heldout_shrink of it); `none` when it closes it so with negligible
/// effects only (not with effects short of decisive evidence);
/// else `unexplained`, listing the effects that close part of it.
/// `v`: stage 5 (significance, and the reason in terms of single fits).
/// Longer than 80 lines (about 100) on purpose: the three verdicts are one
/// decision, and each branch only assembles its own sentence.
void NameEffects(const Explanation& ex, const DiagnoseOptions& options, const Verdict& v, DiagnoseSummary& out) {
  std::vector<std::string> named, negligible, weak, outside, spreads, impossible, symptoms;
  double gain = 0.0;
  for (const ExplanationStep* step : ByEarnings(ex)) {
    const ExplanationStep& s = *step;
    const std::string name = sim::EffectToString(s.effect);
    gain += s.heldout_gain_nats;
    if (!s.unphysical.empty())
      impossible.push_back(name);
    else if (s.negligible)
      negligible.push_back(name);
    else if (s.not_decisive)
      weak.push_back(fmt::format("{} ({:+.1f} nats)", name, s.earned_given_others_nats));
    else if (!s.outside_range.empty())
      outside.push_back(fmt::format("{} ({})", name, s.outside_range));
    else if (!s.spread_of_named.empty())
      spreads.push_back(fmt::format("{} (the spread of {} about its value)", name, s.spread_of_named));
    else
      named.push_back(name);
  }
  for (const ExplanationStep& s : ex.symptoms) symptoms.push_back(sim::EffectToString(s.effect));
  const double heldout = ex.steps.empty() ? 0.0 : ex.steps.back().cumulative_heldout_shrink;
  out.unexplained_fraction = std::clamp(1.0 - heldout, 0.0, 1.0);
  std::vector<std::string> all_impossible = impossible;
  all_impossible.insert(all_impossible.end(), symptoms.begin(), symptoms.end());
  const std::string not_named =
      NotNamedText(negligible, weak, outside, spreads, all_impossible, options.negligible, options.decisive_nats);
  const double gap_after = ex.steps.empty() ? out.gap_score : ex.steps.back().gap_after;
  // A significant residual is excused when the explanation closes at least
  // full_shrink of the held-out gap: the misfit of the named effects' shape
  // (with hundreds of runs a small one is significant), not another cause.
  // Against both the shrinks' reference and the baseline itself
  // (Explanation::baseline_heldout_shrink): a reference that sees a gap the
  // baseline could not see makes every remainder a small part of it (a
  // 2 % scale error beside an unlisted yaw misalignment left G = 602 > 14,
  // under a tenth of the reference's gap).
  const double excused = std::min(heldout, ex.baseline_heldout_shrink);
  const bool closed = !ex.steps.empty() && !ex.symptom_first && (!ex.gap_left || excused >= options.full_shrink) &&
                      (!v.found_by_score || heldout >= options.min_heldout_shrink);
  // Named effects that close the larger part of the gap the score found
  // are the answer's larger part: they are named, and a significant
  // remainder is reported beside them (remainder_significant), never
  // hidden, unless it lies mostly (the same level) in the runs' means and
  // trends: something the same in every run, or drifting, is a systematic
  // cause no listed effect describes, not the noise description's misfit
  // (variances, correlations, tails). `none` still needs the gap closed.
  const bool systematic_left = ex.gap_left && out.remainder_mean_share >= options.min_heldout_shrink;
  const bool mostly = !ex.steps.empty() && !ex.symptom_first && v.found_by_score &&
                      heldout >= options.min_heldout_shrink && !systematic_left;
  // One reading of "a remainder" for the reason, the warning, the summary
  // and the next steps: significant and more than the misfit of the
  // effects' shape (full_shrink).
  out.remainder_significant = !ex.steps.empty() && ex.gap_left && excused < options.full_shrink;
  const std::string left = WhatIsLeft(ex.gap_left, named.size() == 1 ? "leaves" : "leave", heldout, excused,
                                      gap_after, out.null_quantile_alpha, options.full_shrink);
  if (closed && named.empty() && weak.empty() && outside.empty() && spreads.empty() && impossible.empty()) {
    out.verdict = "none";
    out.verdict_reason = fmt::format("the significant gap ({}) is closed by effects too small to matter{}",
                                     v.significance, not_named);
  } else if ((closed || mostly) && !named.empty()) {
    out.verdict = named.front();
    out.verdict_reason = fmt::format(
        "{} {} {:.0f}% of the gap on held-out runs ({:+.1f} nats held out over the baseline) and {}; effects added "
        "one at a time by held-out evidence, fitted jointly; the gap: {}{}",
        fmt::join(named, " + "), named.size() == 1 ? "closes" : "together close", 100.0 * heldout, gain, left,
        v.significance, not_named);
  } else {
    out.verdict = "unexplained";
    out.verdict_reason = v.reason;
    if (ex.symptom_first)
      out.verdict_reason += "; the effect with the most held-out evidence fits only at an impossible value: the "
                            "gap is something the listed effects do not describe, and what comes next only imitates it";
    if (ex.steps.empty())
      out.verdict_reason += fmt::format("; the explanation has no step: {}", ex.stop_reason);
    else if (!named.empty())
      // Say how far the explanation got and why that is not enough, so that
      // the next steps (advice.cpp) and the verdict tell the same story.
      out.verdict_reason += fmt::format(
          "; {} {} {:.0f}% of the gap on held-out runs but {}, so no combination of the listed "
          "effects explains it",
          fmt::join(named, " + "), named.size() == 1 ? "closes" : "together close", 100.0 * heldout,
          WhyNotEnough(named.size() == 1, ex.gap_left, heldout >= options.min_heldout_shrink && systematic_left, gap_after,
                       out.null_quantile_alpha, out.remainder_mean_share, options.min_heldout_shrink));
    out.verdict_reason += not_named;
  }
  out.verdict_effects = out.verdict == "none" ? std::vector<std::string>{} : named;
  if (out.verdict == "none") {
    out.unexplained_fraction = 0.0;
    out.remainder_significant = false;
  }
  if (out.verdict != "none" && out.verdict != "unexplained" && out.remainder_significant)
    out.warnings.push_back(fmt::format(
        "the verdict's effects close {:.0f}% of the gap on held-out runs; the significant remainder (G = {:.1f} > "
        "{:.1f}) is something no listed effect describes",
        100.0 * heldout, gap_after, out.null_quantile_alpha));
  // A weakly identifiable effect the explanation names was told apart by
  // its fits: not "hardly told apart" (stage 5 did not know the names).
  std::erase_if(out.indistinguishable, [&](const std::string& line) {
    return std::any_of(named.begin(), named.end(), [&](const std::string& n) {
      return line.rfind(n + " can hardly be told apart", 0) == 0;
    });
  });
}

/// Which wheel noise is right, the baseline's (bl, br) or the one with the
/// mean effects fitted (kl, kr): what the repeated runs' scatter (a mean
/// effect drops out of it) can say at the level of their check
/// (RepeatDisagreement: two standard errors), or the design that would.
std::string RepeatsAdvice(const RepeatNoise& r, double bl, double br, double kl, double kr) {
  if (!r.measured)
    return "Repeated runs of one path (their scatter about their own mean, where a mean effect drops out) would "
           "measure the wheel noise apart from the pieces (diagnose --hold-wheel-noise)";
  const bool apart = std::abs(bl - kl) > 2.0 * r.sd_k_L || std::abs(br - kr) > 2.0 * r.sd_k_R;
  const bool nearer_fit = std::abs(r.k_L - kl) + std::abs(r.k_R - kr) < std::abs(r.k_L - bl) + std::abs(r.k_R - br);
  return fmt::format(
      "The repeated runs' scatter gives k_L = {:.3g} +- {:.2g}, k_R = {:.3g} +- {:.2g} ({} contrasts): {}", r.k_L,
      r.sd_k_L, r.k_R, r.sd_k_R, r.contrasts,
      !apart ? "the two differ by less than two of its standard errors, so it cannot tell them apart; more repeated "
               "runs of one path would"
      : nearer_fit ? "nearer the wheel noise with the mean effects fitted; diagnose with --hold-wheel-noise to hold k "
                     "there"
                   : "nearer the baseline's, so the mean effects may not be all the difference");
}

/// A named clock whose value in the explanation the moving samples alone
/// (Candidate::ClockCheck: where a slide or a scrub at the stops cannot
/// act) contradict by more than 3 of their standard errors, the check's own
/// level, and by more than the effect's own practical floor at the
/// campaign's speeds (a 0.5 ms difference 5 standard errors out is no
/// reason to re-record): a warning and what to record (docs/diagnosis.md,
/// "The clock's size beside a slide or a turn scrub"). Only effects with
/// one parameter and a check with a standard error (the fixed clock).
std::vector<std::string> ClockDisagreements(const CampaignData& c, double negligible, const DiagnoseSummary& out) {
  const effects::CampaignScale campaign = CampaignScaleOf(c, negligible);
  std::vector<std::string> w;
  for (const ExplanationStep& st : out.explanation) {
    if (st.params.size() != 1 || !Named(out, st.effect)) continue;
    const std::string name = sim::EffectToString(st.effect);
    for (const Candidate& cd : out.candidates) {
      const Candidate::ClockCheck& k = cd.clock;
      if (cd.effect != st.effect || !k.checked || !k.supported || !(k.se > 0.0)) continue;
      const auto& [param, value] = *st.params.begin();
      const double z = (value - k.value) / k.se;
      if (std::abs(z) <= 3.0 || !PracticalFloor(st.effect, {{param, value - k.value}}, campaign).empty()) continue;
      const double d = std::abs(value - k.value);
      w.push_back(fmt::format(
          "{}: the explanation's {} = {:.1f} ms, but the moving samples alone (the ends of {} pieces in a motion's "
          "cruise, where a slide or a scrub at the stops cannot act) give {:.1f} +- {:.1f} ms: {:.1f} ms apart ({:.1f} "
          "of their standard errors; {:.2f} mm at the campaign's {:.2f} m/s, {:.2f} mrad at {:.2f} rad/s). Something at "
          "the stops pulls the fit on all pieces (on the physics engine a sliding stop or a turn scrub did, and the "
          "moving samples were right). Where that difference matters, record runs with long stretches at constant "
          "speed and diagnose them alone before shifting the timestamps",
          name, param, 1e3 * value, k.pieces, 1e3 * k.value, 1e3 * k.se, 1e3 * d, std::abs(z),
          1e3 * d * campaign.speed_mps, campaign.speed_mps, 1e3 * d * campaign.turn_rate_radps,
          campaign.turn_rate_radps));
    }
  }
  return w;
}

/// What the baseline's wheel noise took in (docs/diagnosis.md): a note
/// when a k of the baseline is more than 1.5 x (the level of the repeated
/// runs' check, RepeatDisagreement) the k its pieces show once the
/// explanation's mean effects are fitted, or when the shrinks are measured
/// against the baseline's mean seen with that k (Explanation::
/// reference_held). The baseline fits k_L, k_R with
/// E_d, E_b, so a mean effect it leaves out goes into them and the gap
/// score G, measured against it, understates what that effect closes: on
/// the June session s5 a +1.5 % scale error doubled k_L and left G where it
/// was, and the held-out shrink of the fitted scale error read -28 %.
std::string WheelNoiseTookIn(const Explanation& ex, const DiagnoseSummary& out) {
  if (!ex.mean_wheel_noise_measured) return {};  // measured only with a mean step
  const double kl = ex.mean_wheel_noise_k_L, kr = ex.mean_wheel_noise_k_R;
  const double bl = out.baseline.k_L, br = out.baseline.k_R;
  if (!(bl > 1.5 * kl) && !(br > 1.5 * kr) && !ex.reference_held) return {};
  std::vector<std::string> mean;
  for (const ExplanationStep& st : ex.steps)
    if (!IsNoiseEffect(st.effect)) mean.push_back(sim::EffectToString(st.effect));
  return fmt::format(
      "the baseline's wheel noise (k_L = {:.3g}, k_R = {:.3g} m^1/2) is {:.2g} x / {:.2g} x what its pieces show once "
      "{} {} fitted (k_L = {:.3g}, k_R = {:.3g}): fitted with E_d, E_b, it took part of {} in, so the gap score G, "
      "measured against the baseline, understates what {} ({:.0f}% of it on held-out runs){}; the held-out "
      "evidence (nats) is the measure to read for {}. {}",
      bl, br, bl / std::max(kl, 1e-12), br / std::max(kr, 1e-12), fmt::join(mean, " + "),
      mean.size() == 1 ? "is" : "are", kl, kr, mean.size() == 1 ? "it" : "them",
      mean.size() == 1 ? "it closes" : "they close", 100.0 * ex.baseline_heldout_shrink,
      ex.reference_held ? fmt::format(". So the explanation's shrinks are measured against the baseline's mean seen "
                                      "with that wheel noise: {:.0f}% of the gap closed on held-out runs",
                                      100.0 * ex.steps.back().cumulative_heldout_shrink)
                        : std::string(),
      mean.size() == 1 ? "it" : "them", RepeatsAdvice(out.baseline.repeat, bl, br, kl, kr));
}

/// Stage 6: the stepwise explanation, which effects the verdict names, and
/// what this design cannot separate (turn_scrub from E_b without arcs),
/// unless a weakly identifiable scrub was named on its own evidence.
/// `explained`: the explained model (Explanation::p, noise, bases), left
/// empty without a significant gap.
void ExplainGap(const CampaignData& c, const MeanModel& model, const BaselineFit& base, const Folds& folds,
                const CandidateFits& fits, const Verdict& v, const DiagnoseOptions& options, StageTimer& timer,
                DiagnoseSummary& out, Explanation& explained) {
  out.negligible_threshold = options.negligible;
  if (out.significant) {
    ExplanationOptions eo;
    eo.max_effects = options.max_explanation_effects;
    eo.complexity_penalty_nats = options.complexity_penalty_nats;
    eo.negligible = options.negligible;
    eo.threads = options.threads;
    eo.gap = options.gap;
    eo.keep_heldout_shrink = options.keep_heldout_shrink;
    eo.min_heldout_shrink = options.min_heldout_shrink;
    eo.progress = StageProgress(options.progress, 700.0, 1000.0, 1000.0);
    Explanation ex = Explain(c, model, base, folds, out.candidates, fits.mean_fits, out.gap_score,
                             out.null_median, out.null_quantile_alpha, eo);
    // A step's joint fit has no standard errors of its own; the effect's
    // single-effect fit on the same runs gives them (a joint fit's are no
    // smaller). Without them a turn scrub of k = -0.006 that its single fit
    // puts 2 SE below 0 was named on the June campaign while the same
    // effect was flagged impossible among the candidates.
    for (ExplanationStep& st : ex.steps) {
      std::map<std::string, double> se;
      for (const Candidate& cd : out.candidates)
        if (cd.effect == st.effect) se = cd.param_se;
      st.unphysical = UnphysicalFit(sim::EffectToString(st.effect), st.params, static_cast<int>(c.runs.size()), se);
      // A value outside the physical range that its standard errors excuse
      // is no symptom, but no cause a robot can have either: not named.
      // (Standard errors of 0: the range at the point estimate itself.)
      std::map<std::string, double> exact;
      for (const auto& [name, value] : st.params) exact[name] = 0.0;
      if (st.unphysical.empty())
        st.outside_range =
            UnphysicalFit(sim::EffectToString(st.effect), st.params, static_cast<int>(c.runs.size()), exact);
      st.not_decisive = st.earned_given_others_nats < options.decisive_nats;
    }
    MarkSpreads(c, model, base, ex);
    out.explanation = ex.steps;
    if (!ex.steps.empty()) {
      out.explained_E_d = ex.p[kParamEd];
      out.explained_E_b = ex.p[kParamEb];
      if (!base.given) {
        const RobotParams r = ApplyCorrection(c.robot, out.explained_E_d, out.explained_E_b);
        out.explained_wheelbase_m = r.wheelbase_m;
        out.explained_diameter_left_m = r.wheel_diameter_left_m;
        out.explained_diameter_right_m = r.wheel_diameter_right_m;
      }
    }
    out.explanation_stop = ex.stop_reason;
    out.symptoms = ex.symptoms;
    if (!ex.steps.empty() && ex.bases.size() == c.pieces.size()) {
      // What is left, where: the gap statistics of the explained model.
      std::vector<double> eps;
      model.Residuals(ex.p, eps);
      const GapSummary left = ComputeGap(c, PieceScores(eps, ex.bases, c.pieces, ex.noise), options.gap);
      out.remaining_gap_score = left.score;
      out.remaining_where = LocateGap(c, left, options.where_top);
      const double systematic = left.by_kind[static_cast<int>(StatKind::kMean)] +
                                left.by_kind[static_cast<int>(StatKind::kTrend)];
      out.remainder_mean_share = left.score > 0.0 ? systematic / left.score : 0.0;
    }
    out.shrink_reference = ex.reference_held ? "mean_effects_wheel_noise" : "baseline";
    out.heldout_shrink_against_baseline = ex.baseline_heldout_shrink;
    if (std::string n = WheelNoiseTookIn(ex, out); !n.empty()) out.notes.push_back(std::move(n));
    NameEffects(ex, options, v, out);
    for (std::string& w : ClockDisagreements(c, options.negligible, out)) out.warnings.push_back(std::move(w));
    explained = std::move(ex);
    timer.Lap("stepwise explanation");
  }
  // What the design cannot tell apart, for each effect not named
  // (Effect::DesignNote).
  effects::DesignFacts design = DesignFactsOf(c, base.p[kParamEb]);
  for (const Candidate& cd : out.candidates) {
    if (Named(out, cd.effect)) continue;
    design.separable = cd.identifiable && !cd.weak;
    if (std::string n = effects::Of(cd.effect).DesignNote(design); !n.empty()) out.notes.push_back(std::move(n));
  }
}

/// The ground-truth noise against the standstill scatter
/// (standstill_noise.hpp): a warning when one sd is more than twice or less
/// than half the scatter (beyond the scatter's own sampling error of about
/// 20 % at its fewest 30 differences). Source "standstills": the sigmas the
/// pieces would fit with the wheel noise; else the baseline's own (fitted,
/// or the manifest's).
std::string StandstillDisagreement(const BaselineSummary& b) {
  const StandstillNoise& s = b.standstill;
  if (!s.measured) return {};
  const bool used = b.ground_truth_source == "standstills";
  const double xy = used ? b.pieces_sigma_xy_m : b.sigma_xy_m, th = used ? b.pieces_sigma_theta_rad : b.sigma_theta_rad;
  auto off = [](double a, double ref) { return ref > 0.0 && (a > 2.0 * ref || a < 0.5 * ref); };
  if (!off(xy, s.sigma_xy_m) && !off(th, s.sigma_theta_rad)) return {};
  const std::string what =
      used ? "fitted to the pieces with the wheel noise, the ground truth's noise would be"
           : (b.ground_truth_source == "fitted" ? "the ground truth's noise fitted to the pieces" : "the ground truth's noise stated in the manifest");
  const std::string advice =
      used ? "the pieces hold something the standstills do not (an effect along the pieces or at the stops, or capture "
             "noise that grows with speed); the baseline keeps the standstill scatter, so the gap test sees it"
      : b.ground_truth_source == "fitted"
          ? "the fit takes in something that is not measurement noise (an effect at the stops or along the pieces), "
            "which the gap test then cannot see; state the motion capture's noise in the manifest ([ground_truth] "
            "sigma_xy_m, sigma_theta_rad) and diagnose again"
          : "check the manifest's [ground_truth] values";
  return fmt::format(
      "{} {:.3g} mm, {:.3g} mrad: {:.2g} x / {:.2g} x the scatter measured inside the standstills ({:.3g} mm, {:.3g} "
      "mrad, from {} sample-to-sample differences at least {:.1f} s after a stop): {}",
      what, 1e3 * xy, 1e3 * th, xy / s.sigma_xy_m, th / s.sigma_theta_rad, 1e3 * s.sigma_xy_m, 1e3 * s.sigma_theta_rad,
      s.differences, StandstillNoiseOptions{}.settle_s, advice);
}

/// The wheel noise fitted jointly with the mean on the pieces (the
/// baseline's, or with the source "repeats" the fit beside it) against the
/// repeated runs' scatter (repeat_noise.hpp): a warning when a k differs by
/// more than 1.5 x (either way) and by more than two of the repeated runs'
/// standard errors.
std::string RepeatDisagreement(const BaselineSummary& b) {
  const RepeatNoise& r = b.repeat;
  if (!r.measured || (b.wheel_noise_source != "repeats" && b.wheel_noise_source != "fitted")) return {};
  const bool held = b.wheel_noise_source == "repeats";
  const double kl = held ? b.pieces_k_L : b.k_L, kr = held ? b.pieces_k_R : b.k_R;
  auto off = [](double a, double ref, double sd) {
    return std::abs(a - ref) > 2.0 * sd && (a > 1.5 * ref || a < ref / 1.5);
  };
  if (!off(kl, r.k_L, r.sd_k_L) && !off(kr, r.k_R, r.sd_k_R)) return {};
  return fmt::format(
      "fitted jointly with E_d, E_b on the pieces, the wheel noise {} k_L = {:.3g}, k_R = {:.3g} m^1/2: {:.2g} x / {:.2g} x "
      "the scatter of repeated runs about their own mean (k_L = {:.3g} +- {:.2g}, k_R = {:.3g} +- {:.2g}): the pieces "
      "hold something the same in every run that the baseline leaves out (a mean effect the joint fit takes as wheel "
      "noise), or the runs differ in something of their own (a per-run clock, bumps, settling) that the repeated runs "
      "see and the pieces fit otherwise; {}",
      held ? "would be" : "is", kl, kr, kl / std::max(r.k_L, 1e-12),
      kr / std::max(r.k_R, 1e-12), r.k_L, r.sd_k_L, r.k_R, r.sd_k_R,
      held ? "the baseline keeps the repeated runs' k, so the gap test sees it"
           : "diagnose with --hold-wheel-noise to hold k at the repeated runs' scatter, and compare the verdicts");
}

/// What the standstill scatter's estimate rests on, when it is more than a
/// plain sample-to-sample sd: correlation over samples, a drift, a floor.
std::string StandstillNote(const BaselineSummary& b) {
  const StandstillNoise& s = b.standstill;
  if (!s.measured || b.ground_truth_source != "standstills") return {};
  std::vector<std::string> parts;
  const double tol = 1.0 + StandstillNoiseOptions{}.plateau_tolerance;
  if (s.sigma_xy_m > tol * s.lag1_sigma_xy_m || s.sigma_theta_rad > tol * s.lag1_sigma_theta_rad)
    parts.push_back(fmt::format("the capture noise is correlated over samples: the sample-to-sample scatter ({:.3g} mm, "
                                "{:.3g} mrad) levels off at lags of {} and {} samples ({:.3g} mm, {:.3g} mrad)",
                                1e3 * s.lag1_sigma_xy_m, 1e3 * s.lag1_sigma_theta_rad, s.lag_xy, s.lag_theta,
                                1e3 * s.sigma_xy_m, 1e3 * s.sigma_theta_rad));
  // Normal noise has sd / robust scale 1 within the sampling error (about
  // 20 % at the fewest 30 differences): 1.5 is well beyond it.
  if (s.sigma_xy_m > 1.5 * s.robust_sigma_xy_m || s.sigma_theta_rad > 1.5 * s.robust_sigma_theta_rad)
    parts.push_back(fmt::format("the capture noise is heavy-tailed (the pose jumps now and then, e.g. a rigid body "
                                "re-fitted to other markers): its sd ({:.3g} mm, {:.3g} mrad), which the model uses, is "
                                "{:.2g} x / {:.2g} x the width of its core (1.4826 x the median absolute deviation: {:.3g} "
                                "mm, {:.3g} mrad)",
                                1e3 * s.sigma_xy_m, 1e3 * s.sigma_theta_rad, s.sigma_xy_m / std::max(s.robust_sigma_xy_m, 1e-12),
                                s.sigma_theta_rad / std::max(s.robust_sigma_theta_rad, 1e-12), 1e3 * s.robust_sigma_xy_m,
                                1e3 * s.robust_sigma_theta_rad));
  if (!s.plateau_xy || !s.plateau_theta)
    parts.push_back("the scatter still grows at the longest lag measured (a drift inside the standstills): it is an "
                    "upper end of the capture noise");
  if (s.floored_xy || s.floored_theta)
    parts.push_back("the standstills are (nearly) noise-free: the noise is raised to its floor of 0.01 mm / 0.01 mrad");
  if (parts.empty()) return {};
  return "ground truth's noise taken from the standstills: " + fmt::format("{}", fmt::join(parts, "; "));
}

/// Stage 1b: faults of single runs (run_faults.hpp), first pass: the
/// screen under the baseline of all runs. Its faults are only suspects: an
/// effect the baseline does not model (a marker offset, a scale error) has
/// a footprint that differs from run to run and passes for per-run clocks
/// or markers there; ConfirmRunFaults decides under the explained model.
RunFaultScan ScreenRunFaults(const CampaignData& c, const MeanModel& model, const BaselineFit& base,
                             const DiagnoseOptions& options) {
  RunFaultOptions ro = options.run_faults;
  ro.seed = options.seed;
  return FindRunFaults(c, model, base, ro);
}

/// The baseline with the explained model's mean and noise in its place
/// (residuals and whiteners at them), for the run statistics. The per-run
/// clock spread (run_time_offset's tau_sd) is left out of the noise: it is
/// the spread the test measures the runs against.
BaselineFit UnderExplanation(const CampaignData& c, const MeanModel& model, const BaselineFit& base,
                             const Explanation& ex) {
  BaselineFit b = base;
  b.p = ex.p;
  model.Residuals(b.p, b.eps);
  b.noise = ex.noise;
  b.noise.run_tau2 = 0.0;
  b.W = Whiteners(ex.bases.empty() ? base.bases : ex.bases, c.pieces, b.noise);
  return b;
}

/// Stage 1b, second pass (after the explanation): the run statistics again
/// under the explained model; a run is faulty when it stands out in both
/// passes (each at the campaign false-alarm rate alpha, so together at most
/// alpha). Returns the confirmed faults and, for the suspects it clears, a
/// note naming the effects that explain them.
struct ConfirmedFaults {
  std::vector<RunFault> faults;
  std::string cleared_note;  ///< empty when nothing was cleared
};
ConfirmedFaults ConfirmRunFaults(const CampaignData& c, const MeanModel& model, const BaselineFit& base,
                                 const Explanation& ex, const DiagnoseOptions& options, std::vector<RunFault> suspects) {
  if (ex.steps.empty()) return {std::move(suspects), {}};  // nothing modelled: the explained model is the baseline
  const RunFaultScan second = ScreenRunFaults(c, model, UnderExplanation(c, model, base, ex), options);
  ConfirmedFaults out;
  std::vector<std::string> cleared;
  for (RunFault& f : suspects) {
    const auto it = std::find_if(second.faults.begin(), second.faults.end(),
                                 [&](const RunFault& g) { return g.run == f.run; });
    if (it != second.faults.end()) {
      out.faults.push_back(*it);
      continue;
    }
    cleared.push_back(fmt::format("experiment {} run {} ({} z = {:+.1f} against {:.1f})", f.experiment + 1, f.run_id,
                                  f.statistic, f.z, f.threshold));
  }
  std::vector<std::string> effects;
  for (const ExplanationStep& st : ex.steps) effects.push_back(sim::EffectToString(st.effect));
  if (!cleared.empty())
    out.cleared_note = fmt::format(
        "no faulty run: {} stood out of {} experiment under the baseline, but not once the explanation's effects "
        "({}) are modelled: their footprint differs from run to run, the runs are not faulty",
        fmt::join(cleared, ", "), cleared.size() == 1 ? "its" : "their", fmt::join(effects, ", "));
  return out;
}

/// The campaign without the faulty runs `out.run_faults` when there are
/// any and at least two runs with pieces stay, else nothing.
std::optional<CampaignData> WithoutFaults(const CampaignData& recorded, const DiagnoseSummary& out) {
  if (out.run_faults.empty() || out.run_faults.size() + 2 > recorded.runs.size()) return std::nullopt;
  std::vector<int> drop;
  for (const RunFault& f : out.run_faults) drop.push_back(f.run);
  CampaignData rest = WithoutRuns(recorded, drop);
  if (rest.pieces.empty()) return std::nullopt;
  return rest;
}

DiagnoseSummary DiagnoseCampaign(const CampaignData& recorded, const DiagnoseOptions& options, bool scan_faults);

/// The diagnosis of the campaign without its faulty runs, carrying the
/// faults found on all runs.
DiagnoseSummary WithoutFaultyRuns(const CampaignData& rest, const DiagnoseOptions& options, DiagnoseSummary& first,
                                  const std::string& cleared_note, StageTimer& timer) {
  DiagnoseSummary out = DiagnoseCampaign(rest, options, false);
  if (!cleared_note.empty()) out.notes.insert(out.notes.begin(), cleared_note);
  std::vector<std::string> names;
  for (const RunFault& f : first.run_faults) names.push_back(fmt::format("experiment {} run {}", f.experiment + 1, f.run_id));
  out.notes.insert(out.notes.begin(), fmt::format("{} faulty run{} left out of every fit below: {}",
                                                  first.run_faults.size(), first.run_faults.size() == 1 ? "" : "s",
                                                  fmt::join(names, ", ")));
  std::vector<std::string> steps;
  for (const RunFault& f : first.run_faults)
    steps.push_back(fmt::format("Experiment {} run {} is faulty, not the robot: {}. It is left out of everything else "
                                "in this diagnosis.",
                                f.experiment + 1, f.run_id, f.what));
  out.next_steps.insert(out.next_steps.begin(), steps.begin(), steps.end());
  out.run_faults = std::move(first.run_faults);
  out.run_fault_test = std::move(first.run_fault_test);
  std::vector<std::pair<std::string, double>> t = timer.Finish();
  t.pop_back();  // the first pass' total
  for (auto& [k, v] : t) k = "first pass (all runs): " + k;
  const double total = out.timings.back().second + [&] {
    double s = 0.0;
    for (const auto& [k, v] : t) s += v;
    return s;
  }();
  out.timings.insert(out.timings.begin(), t.begin(), t.end());
  out.timings.back().second = total;
  return out;
}

// The diagnosis as its numbered stages, each a call into its own file. It is
// 111 lines long because each stage's options are filled from DiagnoseOptions here,
// in place, so that every route of a user's option is visible in one place.
DiagnoseSummary DiagnoseCampaign(const CampaignData& recorded, const DiagnoseOptions& options, bool scan_faults) {
  DiagnoseSummary out;
  out.alpha = options.alpha;
  out.seed = options.seed;
  for (std::size_t e = 0; e < recorded.experiments.size(); ++e)
    out.experiment_labels.push_back(fmt::format("{} ({}, {})", e + 1,
                                                ExperimentKindToString(recorded.experiments[e].kind),
                                                recorded.experiments[e].file));
  StageTimer timer;

  // 1. Baseline: fitted to the runs, or the user's model.
  BaselineStart start;
  if (options.given) {
    start.p = GivenParams(recorded.robot, options.given->params);
    start.description = fmt::format("given model ({})", options.given->source);
  } else {
    start = StartBaseline(recorded, options.use_refine);
    out.notes = start.notes;
    timer.Lap("refined calibration (start)");
  }
  StopChoice stops = ChooseStopModel(recorded, start, options);
  const CampaignData& c = stops.body ? *stops.body : recorded;
  const MeanModel& model = *stops.model;
  const BaselineFit base = std::move(stops.base);
  out.stop_model = c.stop_model;
  if (stops.compared)
    out.notes.push_back(fmt::format("encoder stops: {} (log-likelihood {:+.1f} against the other reading)",
                                    StopModelToString(c.stop_model), stops.loglik_margin));
  timer.Lap("baseline fit and stop reading");
  std::vector<RunFault> suspects;
  if (scan_faults) {
    RunFaultScan screen = ScreenRunFaults(c, model, base, options);
    out.run_fault_test = std::move(screen.test);
    suspects = std::move(screen.faults);
    timer.Lap("run faults (screen)");
  }
  out.notes.insert(out.notes.end(), base.notes.begin(), base.notes.end());
  const ReturnCheck returns = CheckReturns(c, model, base);
  out.baseline = Summarise(c, start, base, returns);
  out.baseline.given = options.given;
  if (std::string w = StandstillDisagreement(out.baseline); !w.empty()) out.warnings.push_back(std::move(w));
  if (std::string n = StandstillNote(out.baseline); !n.empty()) out.notes.push_back(std::move(n));
  if (std::string w = RepeatDisagreement(out.baseline); !w.empty()) out.warnings.push_back(std::move(w));
  timer.Lap("baseline predictions");

  // 2. Where, and the gap's null distribution.
  const GapSummary gap = ComputeGap(c, PieceScores(base.eps, base.bases, c.pieces, base.noise), options.gap);
  out.gap_score = gap.score;
  out.gap_by_kind = gap.by_kind;
  out.where = LocateGap(c, gap, options.where_top);
  out.piece_residuals = StandardisedPieceResiduals(c, base);
  const NullDistribution null = SimulateNullDistribution(
      c, model, base,
      NullOptions{options.null_simulations, options.alpha, options.seed, options.threads, options.gap,
                  StageProgress(options.progress, 0.0, 400.0, 1000.0)});
  out.null_simulations = options.null_simulations;
  out.score_p_value = NullPValue(null.sorted, out.gap_score);
  out.null_median = null.median;
  out.null_quantile_alpha = null.quantile_alpha;
  timer.Lap("gap null distribution");

  // 3. Which: candidate effects, cross-validated over runs.
  CandidateOptions co;
  co.effects = options.effects.empty() ? sim::ContractEffects() : options.effects;
  if (options.given && options.effects.empty())
    for (sim::EffectKind k : GivenModelCandidates(*options.given)) co.effects.push_back(k);
  co.complexity_penalty_nats = options.complexity_penalty_nats;
  co.threads = options.threads;
  co.gap = options.gap;
  co.progress = StageProgress(options.progress, 400.0, 700.0, 1000.0);
  const Folds folds = MakeFolds(c);
  const CandidateFits fits = FitCandidates(c, model, base, folds, out.gap_score, out.null_median, co);
  timer.Lap("candidate effects and cross-validation");

  // 4-5. Significance and verdict.
  VerdictOptions vo;
  vo.alpha = options.alpha;
  vo.min_heldout_shrink = options.min_heldout_shrink;
  vo.full_shrink = options.full_shrink;
  vo.likelihood_tests = options.likelihood_tests;
  vo.negligible = options.negligible;
  vo.campaign = CampaignScaleOf(c, options.negligible);
  Verdict v = DecideVerdict(fits, out.score_p_value, out.null_quantile_alpha, vo);
  out.p_value = v.p_value;
  out.tests_p_value = v.tests_p_value;
  out.tests = v.tests;
  out.significant = v.significant;
  out.candidates = v.candidates;
  out.verdict = v.verdict;
  out.verdict_reason = v.reason;
  out.indistinguishable = v.indistinguishable;
  timer.Lap("verdict");

  // 6. Stepwise explanation and practical significance.
  Explanation explained;
  ExplainGap(c, model, base, folds, fits, v, options, timer, out, explained);
  // 1b, confirmed: faulty runs are left out and everything is fitted again.
  if (!suspects.empty()) {
    ConfirmedFaults confirmed = ConfirmRunFaults(c, model, base, explained, options, std::move(suspects));
    out.run_faults = std::move(confirmed.faults);
    timer.Lap("run faults (under the explained model)");
    if (std::optional<CampaignData> rest = WithoutFaults(recorded, out))
      return WithoutFaultyRuns(*rest, options, out, confirmed.cleared_note, timer);
    out.run_faults.clear();
    if (!confirmed.cleared_note.empty()) out.notes.push_back(std::move(confirmed.cleared_note));
  }
  if (options.given) DescribeGivenModel(c, *options.given, out);
  if (options.progress) options.progress(1000.0, 1000.0);
  out.next_steps = AdviseNextSteps(c, out);
  out.timings = timer.Finish();
  return out;
}

}  // namespace

namespace {

/// `plan --check`'s analysis of the campaign (planning/advice.hpp), with
/// the repeated runs' wheel noise (else the baseline's): the effects its runs cannot tell apart and
/// the smallest addition that separates each, added to `indistinguishable`
/// (not for an effect the verdict names: the fits told it apart); and, in
/// `next_steps`, how many more square runs would determine the E_d, E_b
/// correction (the explained model's, else the baseline's) where these runs
/// do not (calibrate's sentence).
void AddDesignAdvice(const CampaignData& c, DiagnoseSummary& s) {
  std::vector<planning::CheckExperiment> x;
  for (std::size_t i = 0; i < c.experiments.size() && i < c.files.size(); ++i)
    x.push_back(planning::MakeCheckExperiment(c.experiments[i].kind, c.experiments[i].side_m,
                                              c.experiments[i].distance_m, c.experiments[i].file, c.files[i]));
  planning::CheckOptions o;
  // How precisely more runs determine E_d, E_b depends on the runs' random
  // scatter, which the repeated runs measure where no mean effect reaches it
  // (repeat_noise.hpp); the baseline's k fitted on the pieces can hold a
  // mean misfit (a 42 mm marker on a June square session: k_L = 0.26 m^1/2
  // against 0.0015 from the repeats, and a 45 % half-width on E_b).
  const RepeatNoise& rep = s.baseline.repeat;
  if (rep.measured && rep.k_L > 0.0 && rep.k_R > 0.0)
    o.noise = WheelNoise{rep.k_L, rep.k_R};
  else if (s.baseline.k_L > 0.0 && s.baseline.k_R > 0.0)
    o.noise = WheelNoise{s.baseline.k_L, s.baseline.k_R};
  if (c.ground_truth) o.ground_truth = planning::GroundTruthModel{true, c.ground_truth->sigma_xy_m, c.ground_truth->sigma_theta_rad};
  // The corrections to determine are the explained model's (fitted with the
  // named effects), as in the concrete changes (advice.cpp AdviceOf): a
  // marker offset the baseline leaves out drives its E_b far off (a 42 mm
  // marker on a June square session: baseline E_b 1.31, explained 1.01),
  // and "record 33 more runs to determine E_b's +31 % correction" would
  // chase the marker.
  const bool explained = !s.explanation.empty() && !s.baseline.given;
  const double E_d = explained ? s.explained_E_d : s.baseline.E_d;
  const double E_b = explained ? s.explained_E_b : s.baseline.E_b;
  for (const auto& [E, into] : {std::pair{E_d, &o.correction_E_d}, std::pair{E_b, &o.correction_E_b}})
    if (std::isfinite(E) && E > 0.0 && E != 1.0) *into = E;
  const planning::DesignAdvice a = planning::Advise(c.robot, x, o, {});
  for (const planning::RecordMore& m : a.check.record_more) s.next_steps.push_back(planning::RecordMoreMessage(m));
  for (const planning::Confusion& k : a.check.cannot_separate) {
    const auto named = [&](const std::string& w) {
      return std::find(s.verdict_effects.begin(), s.verdict_effects.end(), w) != s.verdict_effects.end();
    };
    if (k.kind == "effects" && std::none_of(k.what.begin(), k.what.end(), named))
      s.indistinguishable.push_back(planning::ConfusionMessage(k));
  }
}

}  // namespace

DiagnoseSummary Diagnose(const CampaignData& recorded, const DiagnoseOptions& options) {
  if (auto e = options.Check(); !e.empty()) throw InvalidOptions("diagnose: " + e);
  DiagnoseSummary s = DiagnoseCampaign(recorded, options, options.find_run_faults);
  AddDesignAdvice(recorded, s);
  s.summary = PlainSummary(s);
  return s;
}

}  // namespace umbmark::diag
