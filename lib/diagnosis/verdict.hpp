// Stage "verdict" of the diagnosis.
//  Significance: the gap score G spreads its power over hundreds of
//  statistics, so a small effect that moves one parameter (a noise
//  correlation, say) can hide in it. Beside G, every candidate with a
//  regular likelihood gives a likelihood-ratio test against the baseline
//  (Wilks); the tests are combined by Bonferroni, p_tests = min(1, m min
//  p_e), and with G's own p-value, p = min(1, 2 min(p_G, p_tests)), so the
//  false-alarm rate stays at most alpha.
//  Verdict: `none` when p >= alpha; else `unexplained` until the stepwise
//  explanation (explanation.hpp) names its effects: the verdict IS the
//  explanation (docs/diagnosis.md, "The verdict's rule"), whose first step
//  is chosen by held-out evidence like every other step. This stage ranks
//  the candidates, each fitted alone, for the table (usable first:
//  identifiable; a clock the moving samples support; a noise effect whose
//  footprint the data do not contradict, footprint.hpp; then those that
//  would close the gap alone; then by evidence), and names nothing. A test
//  whose fit lies below its practical floor (a 0.2 ms clock), or a clock
//  the moving samples do not support, counts in the Bonferroni factor but
//  is no evidence. Effects the data cannot tell apart are listed.
#pragma once

#include <string>
#include <vector>

#include "diagnosis/candidates.hpp"
#include "effects/effect.hpp"

namespace umbmark::diag {

struct VerdictOptions {
  /// False-alarm rate. Default 0.01.
  double alpha = 0.01;
  /// A candidate "would close the gap alone" (the table's order) when it
  /// closes at least this fraction of the held-out gap... Default 0.5.
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
};

struct Verdict {
  double p_value = 1.0;        ///< combined
  double tests_p_value = 1.0;  ///< Bonferroni over the tested candidates
  int tests = 0;
  bool significant = false;
  std::vector<Candidate> candidates;  ///< ranked, best first
  std::string verdict;                ///< none | unexplained (the explanation names effects)
  std::string reason;
  /// The combined p-value in words ("p = ...: gap score ..., likelihood-ratio
  /// tests ... (Bonferroni over m)").
  std::string significance;
  /// Whether the gap score G alone found the gap (p_G below its share of
  /// alpha): the explanation must then also close the held-out gap G
  /// measures; when only the likelihood-ratio tests found it, G is no
  /// measure of it and held-out evidence with the residual test decide.
  bool found_by_score = false;
  std::vector<std::string> indistinguishable;
};

/// score_p_value: G against its null; null_quantile_alpha: G at the null's
/// 1 - alpha quantile.
Verdict DecideVerdict(const CandidateFits& fits, double score_p_value, double null_quantile_alpha,
                      const VerdictOptions& options);

}  // namespace umbmark::diag
