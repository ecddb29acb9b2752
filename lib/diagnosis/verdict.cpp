// Significance and verdict of the diagnosis (see verdict.hpp).
#include "diagnosis/verdict.hpp"

#include "diagnosis/explanation.hpp"
#include "effects/registry.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Dense>
#include <fmt/format.h>

namespace umbmark::diag {

namespace {

/// "p = 0.0123", or "p < 1e-12" beyond what the tail approximations and
/// double precision can vouch for.
std::string P(double p) { return p < 1e-12 ? std::string("p < 1e-12") : fmt::format("p = {:.3g}", p); }

/// Combined p-value of G and the likelihood-ratio tests. A test whose fit
/// lies far outside the physical range (Candidate::impossible) counts in
/// the Bonferroni factor but not as evidence: Wilks' chi^2 holds for
/// alternatives near the baseline, and such a fit is another likelihood
/// mode. A clean campaign from an independent simulator (10 Hz, 500
/// ticks/rev) was called `unexplained` on a turn scrub of k = -1.01 with
/// E_b = 2.0 (LR p = 1.2e-6) while its gap score lay at its null (G =
/// 2.7, p = 0.42). A scrub slightly below 0 still counts (it imitates a
/// real gap; test_diagnose), and the gap score sees every gap.
void Significance(const CandidateFits& fits, double score_p_value, const VerdictOptions& options, Verdict& out) {
  {
    double min_p = 1.0;
    out.tests = 0;
    for (const Candidate& cd : fits.candidates)
      if (cd.tested) {
        ++out.tests;
        effects::CampaignScale campaign = options.campaign;
        campaign.negligible = options.negligible;
        const bool negligible = !PracticalFloor(cd.effect, cd.params, campaign).empty() || !cd.clock.supported;
        if (!cd.impossible && !negligible) min_p = std::min(min_p, cd.lr_p_value);
      }
    out.tests_p_value = std::min(1.0, out.tests * min_p);
    out.p_value = options.likelihood_tests && out.tests > 0
                      ? std::min(1.0, 2.0 * std::min(score_p_value, out.tests_p_value))
                      : score_p_value;
    out.significant = out.p_value < options.alpha;
  }
}

/// Why the verdict is `unexplained` (best: the top candidate, if
/// identifiable), naming a clock offset the moving samples do not support
/// when it was the candidate with the most evidence.
std::string UnexplainedReason(const Verdict& out, const Candidate* best, const std::string& p_text,
                              double null_quantile_alpha) {
  // The candidate with the most evidence, when it is a clock offset the
  // moving samples do not support: say so (the verdict's footprint rule).
  const Candidate* clock = nullptr;
  for (const Candidate& cd : out.candidates)
    if (cd.identifiable && (!clock || cd.evidence > clock->evidence)) clock = &cd;
  if (clock && clock->clock.supported) clock = nullptr;
  std::string reason =
      !best ? fmt::format("significant gap ({}) and no identifiable candidate", p_text)
            : fmt::format("significant gap ({}); fitted alone, the best candidate, {}, closes {:.0f}% of it on "
                          "held-out runs ({:+.1f} nats of held-out evidence) and leaves G = {:.1f} ({} {:.1f})",
                          p_text, sim::EffectToString(best->effect), 100.0 * best->heldout_shrink, best->evidence,
                          best->gap_after, best->gap_after > null_quantile_alpha ? ">" : "<=", null_quantile_alpha);
  if (clock)
    reason += fmt::format("; {} would close {:.0f}% held out, but {}", sim::EffectToString(clock->effect),
                              100.0 * clock->heldout_shrink, clock->clock.text);
  // Likewise a noise effect whose footprint the data contradict.
  for (const Candidate& cd : out.candidates)
    if (cd.identifiable && cd.footprint.checked && !cd.footprint.consistent) {
      reason += fmt::format("; the noise effects would close up to {:.0f}% held out, but {}",
                            100.0 * cd.heldout_shrink, cd.footprint.text);
      break;
    }
  return reason;
}

/// The candidates' order, best first, for the table and the pairs that
/// explain the gap about equally well: usable (identifiable; a clock the
/// moving samples support; a noise effect whose footprint the data do not
/// contradict) first, then those that would close the gap alone
/// (`qualifies`), then by held-out evidence. It names nothing: the verdict
/// is the explanation's (explanation.hpp, docs/diagnosis.md "The verdict's
/// rule"), whose first step is chosen by evidence alone.
template <typename Qualifies>
std::vector<std::size_t> Rank(const CandidateFits& fits, const Qualifies& qualifies) {
  std::vector<std::size_t> rank(fits.candidates.size());
  for (std::size_t i = 0; i < rank.size(); ++i) rank[i] = i;
  auto usable = [](const Candidate& cd) { return cd.identifiable && cd.clock.supported && cd.footprint.consistent; };
  std::stable_sort(rank.begin(), rank.end(), [&](std::size_t a, std::size_t b) {
    const Candidate &ca = fits.candidates[a], &cb = fits.candidates[b];
    if (usable(ca) != usable(cb)) return usable(ca);
    if (qualifies(ca) != qualifies(cb)) return qualifies(ca);
    return ca.evidence > cb.evidence;
  });
  return rank;
}

/// Ranks the candidates; `none` without a significant gap, else
/// `unexplained` until the explanation names its effects (diagnose.cpp
/// NameEffects), with the reason in terms of the single-effect fits.
void Decide(const CandidateFits& fits, double score_p_value, double null_quantile_alpha, const VerdictOptions& options,
            Verdict& out) {
  // Would close the gap alone: closes most of the held-out gap with
  // positive evidence and leaves no significant gap (or nearly none of it).
  auto qualifies = [&](const Candidate& cd) {
    return cd.identifiable && cd.clock.supported && cd.footprint.consistent && cd.evidence > 0.0 &&
           cd.heldout_shrink >= options.min_heldout_shrink &&
           (cd.gap_after <= null_quantile_alpha || cd.heldout_shrink >= options.full_shrink);
  };
  for (std::size_t i : Rank(fits, qualifies)) out.candidates.push_back(fits.candidates[i]);
  out.significance =
      options.likelihood_tests && out.tests > 0
          ? fmt::format("{}: gap score {}, likelihood-ratio tests {} (Bonferroni over {})", P(out.p_value),
                        P(score_p_value), P(out.tests_p_value), out.tests)
          : P(out.p_value);
  // The gap score found the gap on its own (at its half of alpha when both
  // routes are combined): the explanation must then close it held out too.
  const double route_alpha = options.likelihood_tests && out.tests > 0 ? 0.5 * options.alpha : options.alpha;
  out.found_by_score = score_p_value < route_alpha;
  if (!out.significant) {
    out.verdict = "none";
    out.reason = fmt::format("the gap is not significant ({} >= alpha = {})", out.significance, options.alpha);
    return;
  }
  const Candidate* best =
      out.candidates.empty() || !out.candidates.front().identifiable ? nullptr : &out.candidates.front();
  out.verdict = "unexplained";
  out.reason = UnexplainedReason(out, best, out.significance, null_quantile_alpha);
}

/// The part of a candidate's note from the effect it is "indistinguishable
/// from" on, when that is an effect (the registry knows its name), else
/// empty.
std::string OtherEffectInNote(const std::string& note) {
  static constexpr std::string_view kFrom = "indistinguishable from ";
  const std::size_t at = note.find(kFrom);
  if (at == std::string::npos) return {};
  const std::string rest = note.substr(at + kFrom.size());
  const std::size_t end = rest.find_first_not_of("abcdefghijklmnopqrstuvwxyz_");
  return effects::Find(rest.substr(0, end)) != nullptr ? rest : std::string();
}

/// What the data cannot tell apart: effects from the baseline, or from
/// each other (footprints, or held-out evidence).
void Indistinguishable(const CandidateFits& fits, const VerdictOptions& options, Verdict& out) {
  for (const Candidate& cd : out.candidates)
    if (!cd.identifiable && cd.note.find("baseline") != std::string::npos)
      out.indistinguishable.push_back(fmt::format("{} cannot be told apart from the baseline with these experiments: {}",
                                                  sim::EffectToString(cd.effect),
                                                  cd.note.substr(cd.note.find("indistinguishable"))));
    else if (const std::string other = OtherEffectInNote(cd.note); !cd.identifiable && !other.empty())
      out.indistinguishable.push_back(fmt::format("{} cannot be told apart from {}", sim::EffectToString(cd.effect),
                                                  other));
    else if (cd.weak && sim::EffectToString(cd.effect) != out.verdict)
      out.indistinguishable.push_back(
          fmt::format("{} can hardly be told apart from the baseline with these experiments: {}",
                      sim::EffectToString(cd.effect), cd.note.substr(cd.note.find("mostly"))));
  for (std::size_t a = 0; a < fits.candidates.size(); ++a)
    for (std::size_t b = a + 1; b < fits.candidates.size(); ++b) {
      if (!fits.candidates[a].identifiable || !fits.candidates[b].identifiable) continue;
      if (fits.projected[a].size() == 0 || fits.projected[b].size() == 0) continue;
      // Largest canonical correlation between the two effects' footprints
      // (after removing what E_d, E_b explain).
      const Eigen::HouseholderQR<Eigen::MatrixXd> qa(fits.projected[a]), qb(fits.projected[b]);
      const Eigen::MatrixXd Qa = qa.householderQ() * Eigen::MatrixXd::Identity(fits.projected[a].rows(), fits.projected[a].cols());
      const Eigen::MatrixXd Qb = qb.householderQ() * Eigen::MatrixXd::Identity(fits.projected[b].rows(), fits.projected[b].cols());
      const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Qa.transpose() * Qb);
      const double cc = svd.singularValues().size() > 0 ? svd.singularValues()[0] : 0.0;
      if (cc > 0.95)
        out.indistinguishable.push_back(fmt::format(
            "{} and {} leave nearly the same footprint on these data (canonical correlation {:.3f})",
            sim::EffectToString(fits.candidates[a].effect), sim::EffectToString(fits.candidates[b].effect), cc));
    }
  if (out.significant && !out.candidates.empty() && out.candidates.front().identifiable) {
    const Candidate& top = out.candidates.front();
    for (std::size_t i = 1; i < out.candidates.size(); ++i) {
      const Candidate& o = out.candidates[i];
      // Only what could be named: a clock the moving samples do not show, or
      // a noise effect whose footprint the runs contradict, is no rival.
      if (!o.identifiable || o.heldout_shrink < options.min_heldout_shrink || !o.clock.supported ||
          !o.footprint.consistent)
        continue;
      if (std::abs(top.evidence - o.evidence) < 2.0)
        out.indistinguishable.push_back(fmt::format(
            "{} and {} explain the gap about equally well on held-out runs ({:.1f} vs {:.1f} nats)",
            sim::EffectToString(top.effect), sim::EffectToString(o.effect), top.evidence, o.evidence));
    }
  }
}

}  // namespace

Verdict DecideVerdict(const CandidateFits& fits, double score_p_value, double null_quantile_alpha,
                      const VerdictOptions& options) {
  Verdict out;
  Significance(fits, score_p_value, options, out);
  Decide(fits, score_p_value, null_quantile_alpha, options, out);
  Indistinguishable(fits, options, out);
  return out;
}

}  // namespace umbmark::diag
