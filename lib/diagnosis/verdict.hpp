// Stage "verdict" of the diagnosis.
//  Significance: the gap score G spreads its power over hundreds of
//  statistics, so a small effect that moves one parameter (a noise
//  correlation, say) can hide in it. Beside G, every candidate with a
//  regular likelihood gives a likelihood-ratio test against the baseline
//  (Wilks); the tests are combined by Bonferroni, p_tests = min(1, m min
//  p_e), and with G's own p-value, p = min(1, 2 min(p_G, p_tests)), so the
//  false-alarm rate stays at most alpha.
//  Verdict: `none` when p >= alpha; else the top candidate if it closes
//  enough of the held-out gap and leaves no significant gap; else the
//  likelihood-ratio route; else `unexplained`. Candidates rank by whether
//  they are usable (identifiable; a clock the moving samples support; a
//  noise effect whose footprint the data do not contradict, footprint.hpp),
//  then whether they qualify, then by evidence; then a noise effect on top
//  yields to a qualifying mechanism at the starts and stops of motions
//  (castor_kick, castor_swivel, stop_slide: a shift with the turn's or the
//  drive's sign, which kicks that vary imitate as scatter: DART's swivel
//  castors read as bumps), and a slide on top yields to a qualifying clock
//  the moving samples support (which explains the stops too). A test whose
//  fit lies below its practical floor (a 0.2 ms clock), or a clock the
//  moving samples do not support, counts in the Bonferroni factor but is no
//  evidence. Effects the data cannot tell apart are listed.
#pragma once

#include <string>
#include <vector>

#include "diagnosis/candidates.hpp"
#include "effects/effect.hpp"

namespace umbmark::diag {

struct VerdictOptions {
  /// False-alarm rate. Default 0.01.
  double alpha = 0.01;
  /// A winner closes at least this fraction of the held-out gap. Default 0.5.
  double min_heldout_shrink = 0.5;
  /// ...and leaves no significant gap unless it closes this much. Default 0.9.
  double full_shrink = 0.9;
  /// Combine G with the likelihood-ratio tests. Default true.
  bool likelihood_tests = true;
  /// DiagnoseOptions::negligible: a test whose fit is below its practical
  /// floor (explanation.hpp PracticalFloor) is no evidence of a gap that
  /// matters. Default 0.25.
  double negligible = 0.25;
  /// The campaign's speeds and distances for those floors (its negligible
  /// is this struct's). Default: CampaignScale's.
  effects::CampaignScale campaign;
  /// A mechanism at the starts and stops of motions (castor_kick,
  /// castor_swivel, stop_slide) that closes at least this fraction of the
  /// held-out gap alone outranks a qualifying noise effect even when it
  /// leaves scatter behind (kicks that vary from start to start: the noise
  /// effect beside it takes the scatter). Default 0.8.
  double mechanism_shrink = 0.8;
};

struct Verdict {
  double p_value = 1.0;        ///< combined
  double tests_p_value = 1.0;  ///< Bonferroni over the tested candidates
  int tests = 0;
  bool significant = false;
  std::vector<Candidate> candidates;  ///< ranked, best first
  std::string verdict;                ///< effect name | none | unexplained
  std::string reason;
  std::vector<std::string> indistinguishable;
};

/// score_p_value: G against its null; null_quantile_alpha: G at the null's
/// 1 - alpha quantile.
Verdict DecideVerdict(const CandidateFits& fits, double score_p_value, double null_quantile_alpha,
                      const VerdictOptions& options);

}  // namespace umbmark::diag
