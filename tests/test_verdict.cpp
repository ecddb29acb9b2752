// Stage 5 (diagnosis/verdict.hpp) on hand-made candidate tables: which
// likelihood-ratio tests count as evidence of a significant gap, and the
// candidates' order, which names nothing: the verdict is the explanation's
// (docs/diagnosis.md, "The verdict's rule"; test_diagnose_verdict_rule.cpp).
#include <catch2/catch.hpp>

#include <algorithm>
#include <vector>

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

  // The same fit at a possible value is evidence: significant, found by
  // the tests and not by the gap score. (Before the verdict's one rule this
  // stage named the scrub by its own test, the "likelihood-ratio route";
  // now the explanation names what it admits, the first step by held-out
  // evidence like every other.)
  fits.candidates[0].impossible = false;
  const Verdict w = DecideVerdict(fits, score_p, null_q, VerdictOptions{});
  CHECK_THAT(w.tests_p_value, WithinRel(2 * 1.2e-6, 1e-12));
  CHECK_THAT(w.p_value, WithinRel(2 * 2 * 1.2e-6, 1e-12));
  CHECK(w.significant);
  CHECK_FALSE(w.found_by_score);
  CHECK(w.verdict == "unexplained");
}

TEST_CASE("verdict: the gap score's own route is at half of alpha", "[diagnose][verdict]") {
  // p = min(1, 2 min(p_G, p_tests)): G found the gap when p_G < alpha / 2.
  CandidateFits fits;
  fits.candidates.push_back(Tested(umbmark::sim::EffectKind::kTurnScrub, 0.5, false));
  fits.projected.resize(1);
  const Verdict a = DecideVerdict(fits, 0.004, 13.3, VerdictOptions{});
  CHECK(a.significant);
  CHECK(a.found_by_score);
  const Verdict b = DecideVerdict(fits, 0.0049, 13.3, VerdictOptions{});
  CHECK(b.significant);  // 2 x 0.0049 < 0.01
  CHECK(b.found_by_score);
  const Verdict c = DecideVerdict(fits, 0.006, 13.3, VerdictOptions{});
  CHECK_FALSE(c.significant);
  CHECK_FALSE(c.found_by_score);
  CHECK(c.verdict == "none");
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

namespace {

/// The effects in the order the stage ranks them.
std::vector<umbmark::sim::EffectKind> Order(const Verdict& v) {
  std::vector<umbmark::sim::EffectKind> out;
  for (const Candidate& c : v.candidates) out.push_back(c.effect);
  return out;
}

}  // namespace

TEST_CASE("verdict: stage 5 names nothing and promotes nothing: candidates rank by evidence",
          "[diagnose][verdict]") {
  using umbmark::sim::EffectKind;
  // DART's swivel castor: bumps with more evidence than castor_swivel. The
  // stage once promoted the start/stop mechanism above the noise effect
  // (VerdictOptions::mechanism_shrink, 0.8, set between DART campaigns);
  // now the evidence orders them and the explanation names them both
  // (test_dart_campaigns).
  const Verdict v = Decide({Qualifying(EffectKind::kCastorSwivel, 600.0), Qualifying(EffectKind::kBumpOutliers, 900.0)});
  CHECK(v.significant);
  CHECK(v.verdict == "unexplained");  // until the explanation names its effects
  CHECK(Order(v) == std::vector<EffectKind>{EffectKind::kBumpOutliers, EffectKind::kCastorSwivel});
  // A third candidate does not change the order of two others, wherever it
  // ranks itself (the order is one sort on each candidate's own numbers).
  for (double third : {100.0, 700.0, 1000.0}) {
    const Verdict w = Decide({Qualifying(EffectKind::kCastorSwivel, 600.0), Qualifying(EffectKind::kTimeOffset, third),
                              Qualifying(EffectKind::kBumpOutliers, 900.0)});
    const auto o = Order(w);
    INFO(third);
    CHECK(std::find(o.begin(), o.end(), EffectKind::kBumpOutliers) <
          std::find(o.begin(), o.end(), EffectKind::kCastorSwivel));
  }
}

TEST_CASE("verdict: a slide and a clock rank by evidence, an unsupported clock ranks last", "[diagnose][verdict]") {
  using umbmark::sim::EffectKind;
  Candidate clock = Qualifying(EffectKind::kRunTimeOffset, 400000.0, 0.999);
  clock.clock.checked = true;
  const Candidate slide = Qualifying(EffectKind::kStopSlide, 411000.0, 0.999);
  // No yield of a slide to a clock (the stage once put a supported clock
  // first whatever the evidence).
  CHECK(Order(Decide({clock, slide})).front() == EffectKind::kStopSlide);
  clock.evidence = 420000.0;
  CHECK(Order(Decide({slide, clock})).front() == EffectKind::kRunTimeOffset);
  clock.clock.supported = false;  // the moving samples do not show it: not usable
  const Verdict v = Decide({clock, slide});
  CHECK(Order(v).front() == EffectKind::kStopSlide);
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
