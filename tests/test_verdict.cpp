// The verdict's significance rule (diagnosis/verdict.hpp) on hand-made
// candidate tables: which likelihood-ratio tests count as evidence.
#include <catch2/catch.hpp>

#include "diagnosis/verdict.hpp"

using namespace umbmark::diag;
using Catch::Matchers::WithinRel;

namespace {

/// A tested candidate as FitCandidates leaves it, with the given LR p.
Candidate Tested(umbmark::sim::EffectKind kind, double lr_p, bool impossible) {
  Candidate c;
  c.effect = kind;
  c.tested = true;
  c.parameters = 1;
  c.lr_p_value = lr_p;
  c.impossible = impossible;
  c.heldout_loglik_gain = 11.0;
  c.evidence = 9.0;
  c.heldout_shrink = -1.0;  // fits better in likelihood, widens the gap score
  c.gap_after = 5.0;
  return c;
}

}  // namespace

TEST_CASE("verdict: an impossible fit's likelihood-ratio test is no evidence of a gap", "[diagnose][verdict]") {
  // The case from the independent generator's clean campaign 777/004 (10 Hz,
  // 500 ticks/rev): G far below its null (p = 0.42), and a turn scrub that
  // reached k = -1.01 with E_b = 2.0, LR p = 1.2e-6. Before the rule the
  // combined p was 4.8e-6 and the diagnosis `unexplained`.
  const double score_p = 0.42, null_q = 13.3;
  CandidateFits fits;
  fits.candidates.push_back(Tested(umbmark::sim::EffectKind::kTurnScrub, 1.2e-6, /*impossible=*/true));
  fits.candidates.push_back(Tested(umbmark::sim::EffectKind::kScaleError, 0.3, false));
  fits.projected.resize(2);
  const Verdict v = DecideVerdict(fits, score_p, null_q, VerdictOptions{});
  CHECK(v.tests == 2);  // still counted in the Bonferroni factor
  CHECK_THAT(v.tests_p_value, WithinRel(2 * 0.3, 1e-12));
  CHECK_FALSE(v.significant);
  CHECK(v.verdict == "none");

  // The same fit at a possible value is evidence: significant, and found
  // by its own test (before the rule this stage named the scrub, and
  // diagnose.cpp's NameEffects turned the impossible name into
  // `unexplained`).
  fits.candidates[0].impossible = false;
  const Verdict w = DecideVerdict(fits, score_p, null_q, VerdictOptions{});
  CHECK_THAT(w.tests_p_value, WithinRel(2 * 1.2e-6, 1e-12));
  CHECK_THAT(w.p_value, WithinRel(2 * 2 * 1.2e-6, 1e-12));
  CHECK(w.significant);
  CHECK(w.verdict == "turn_scrub");
}

TEST_CASE("verdict: an impossible fit is never found by its own likelihood-ratio test", "[diagnose][verdict]") {
  // A significant gap that no candidate closes (score p = 1e-4), and one
  // candidate whose own LR test would name it alone (found_alone in
  // verdict.cpp: significant, gains held out, leaves no significant G).
  CandidateFits fits;
  Candidate c = Tested(umbmark::sim::EffectKind::kTurnScrub, 1e-8, false);
  c.heldout_shrink = 0.2;
  c.gap_after = 3.0;
  fits.candidates.push_back(c);
  fits.projected.resize(1);
  const Verdict found = DecideVerdict(fits, 1e-4, 13.3, VerdictOptions{});
  CHECK(found.verdict == "turn_scrub");
  fits.candidates[0].impossible = true;
  const Verdict symptom = DecideVerdict(fits, 1e-4, 13.3, VerdictOptions{});
  CHECK(symptom.significant);  // the gap score alone
  CHECK(symptom.verdict == "unexplained");
}

namespace {

/// A candidate that qualifies on its own: closes `shrink` of the held-out
/// gap, leaves no significant gap, with `evidence` nats.
Candidate Qualifying(umbmark::sim::EffectKind kind, double evidence, double shrink = 0.95) {
  Candidate c = Tested(kind, 1e-12, false);
  c.evidence = evidence;
  c.heldout_shrink = shrink;
  c.gap_after = 3.0;
  return c;
}

Verdict Decide(const std::vector<Candidate>& cands) {
  CandidateFits fits;
  fits.candidates = cands;
  fits.projected.resize(cands.size());
  return DecideVerdict(fits, 1e-12, 13.3, VerdictOptions{});
}

}  // namespace

TEST_CASE("verdict: a noise effect yields to a start/stop mechanism that also qualifies", "[diagnose][verdict]") {
  using umbmark::sim::EffectKind;
  // DART's swivel castor: kicks that vary from start to start read as bumps
  // with more evidence, but bumps have no turn's sign.
  CHECK(Decide({Qualifying(EffectKind::kBumpOutliers, 900.0), Qualifying(EffectKind::kCastorSwivel, 600.0)}).verdict ==
        "castor_swivel");
  // Not at an impossible value (a symptom), and not when it does not qualify.
  Candidate impossible = Qualifying(EffectKind::kCastorSwivel, 600.0);
  impossible.impossible = true;
  CHECK(Decide({Qualifying(EffectKind::kBumpOutliers, 900.0), impossible}).verdict == "bump_outliers");
  CHECK(Decide({Qualifying(EffectKind::kBumpOutliers, 900.0), Qualifying(EffectKind::kCastorSwivel, 600.0, 0.05)})
            .verdict == "bump_outliers");
  // Mean effects other than the start/stop mechanisms keep the evidence
  // order (a scale error does not outrank bumps: DART's floor strips).
  CHECK(Decide({Qualifying(EffectKind::kBumpOutliers, 900.0), Qualifying(EffectKind::kScaleError, 600.0)}).verdict ==
        "bump_outliers");
  // The order of the input does not matter (the ranking is one sort, then
  // the promotion).
  CHECK(Decide({Qualifying(EffectKind::kCastorSwivel, 600.0), Qualifying(EffectKind::kTimeOffset, 700.0),
                Qualifying(EffectKind::kBumpOutliers, 900.0)})
            .verdict == "castor_swivel");
  CHECK(Decide({Qualifying(EffectKind::kBumpOutliers, 900.0), Qualifying(EffectKind::kTimeOffset, 700.0),
                Qualifying(EffectKind::kCastorSwivel, 600.0)})
            .verdict == "castor_swivel");
}

TEST_CASE("verdict: a slide yields to a clock the moving samples support; an unsupported clock is never named",
          "[diagnose][verdict]") {
  using umbmark::sim::EffectKind;
  Candidate clock = Qualifying(EffectKind::kRunTimeOffset, 400000.0, 0.999);
  clock.clock.checked = true;
  const Candidate slide = Qualifying(EffectKind::kStopSlide, 411000.0, 0.999);
  // The ground truth lags on through every stop by v tau: a slide imitates
  // it at the stops, but only the clock explains the moving samples.
  CHECK(Decide({slide, clock}).verdict == "run_time_offset");
  clock.clock.supported = false;  // the moving samples do not show it
  CHECK(Decide({slide, clock}).verdict == "stop_slide");
  clock.evidence = 500000.0;
  CHECK(Decide({clock, slide}).verdict == "stop_slide");
}

TEST_CASE("verdict: a noise effect whose footprint the data contradict is never named", "[diagnose][verdict]") {
  using umbmark::sim::EffectKind;
  Candidate floor = Qualifying(EffectKind::kMotionNoiseFloor, 30.0);
  floor.footprint.checked = true;
  floor.footprint.consistent = false;
  floor.footprint.text = "adjacent stretches of the legs have heading errors that cancel";
  const Verdict v = Decide({floor});
  CHECK(v.significant);
  CHECK(v.verdict == "unexplained");
  CHECK(v.reason.find("cancel") != std::string::npos);
}

TEST_CASE("verdict: a start/stop mechanism that closes most of the gap outranks the noise effect that takes its scatter",
          "[diagnose][verdict]") {
  using umbmark::sim::EffectKind;
  // DART's swivel castors whose kicks vary from start to start: bumps close
  // 99.9 % (+3046 nats), castor_swivel alone 89.7 % (+1880 nats) and leaves
  // a significant gap, so it does not qualify on its own.
  Candidate swivel = Qualifying(EffectKind::kCastorSwivel, 1880.0, 0.897);
  swivel.gap_after = 500.0;
  const Verdict v = Decide({Qualifying(EffectKind::kBumpOutliers, 3046.0, 0.999), swivel});
  CHECK(v.verdict == "castor_swivel");
  CHECK(v.reason.find("ranked before bump_outliers") != std::string::npos);
  // Below VerdictOptions::mechanism_shrink (0.8) it does not: DART's floor
  // strips fit castor_swivel at 55-64 % held out.
  swivel.heldout_shrink = 0.64;
  CHECK(Decide({Qualifying(EffectKind::kBumpOutliers, 3046.0, 0.999), swivel}).verdict == "bump_outliers");
  // Nor when nothing qualifies to take the scatter: the mechanism alone
  // leaves a significant gap, so the verdict is unexplained.
  swivel.heldout_shrink = 0.897;
  Candidate bumps = Qualifying(EffectKind::kBumpOutliers, 3046.0, 0.4);
  bumps.gap_after = 500.0;
  CHECK(Decide({bumps, swivel}).verdict == "unexplained");
}
