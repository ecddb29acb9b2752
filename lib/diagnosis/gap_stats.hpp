// Where the data leave the model: standardised piece scores and the
// localised statistics of the gap.
//
// Scores: each piece's residual eps (model.hpp) is whitened with the
// Cholesky factor of its model covariance in the order (heading, x, y), so
// the three scores are
//   heading                 theta / sd(theta)
//   along-track | heading   x given theta
//   lateral | heading       y given theta and x
// independent N(0, 1) per piece when the model is right. Under the
// bump_outliers mixture the whitening uses the mixture's covariance and each
// score is mapped through its mixture CDF to N(0, 1) (probability integral
// transform), so the same statistics apply to every model.
//
// Statistics, per experiment and subset (cw/ccw or forward/backward leg x
// straight first/later pieces, spot turn, arc, standstill) and component,
// each as a z-value (size in standard errors under the model):
//   mean         sum z / sqrt(n)
//   variance     (mean z^2 - 1) / sqrt(2/n)
//   correlation  sum z_a z_b / sqrt(n)        (pairs of components)
//   tail         count of |z| > 3 against Binomial(n, 0.27%): upper-tail
//                probability as a one-sided normal score
//   trend        weighted regression slope of the per-run mean score on the
//                run's index in its experiment (early vs late runs) / its SE
// The gap score sums the excess over `threshold_se` standard errors:
//   G = sum over statistics of max(0, |z| - threshold_se)^2
// (about 0.017 per statistic under the model for threshold 2).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "diagnosis/pieces.hpp"
#include "diagnosis/piece_noise.hpp"

namespace umbmark::diag {

enum class StatKind { kMean, kVariance, kCorrelation, kTail, kTrend };
inline constexpr int kNumStatKinds = 5;
const char* StatKindToString(StatKind k);

/// Component names in score order: heading, along-track, lateral.
const char* ComponentName(int c);

/// Scores of one piece (NaN for a component the piece does not have).
using Scores = std::array<double, 3>;

/// Scores of every piece given residuals and the noise model.
std::vector<Scores> PieceScores(const std::vector<double>& eps, const std::vector<PieceBases>& bases,
                                const std::vector<Piece>& pieces, const NoiseParams& noise);

struct GapStatistic {
  int subset = 0;
  StatKind kind = StatKind::kMean;
  int comp_a = 0, comp_b = -1;  ///< comp_b for correlations
  double z = 0.0;
  int n = 0;  ///< pieces (runs for trends)
};

struct GapSummary {
  std::vector<GapStatistic> stats;
  double score = 0.0;
  std::array<double, kNumStatKinds> by_kind{};  ///< score split by statistic kind
};

struct GapOptions {
  /// Statistics count towards the score beyond this many SE. Default 2.
  double threshold_se = 2.0;
  /// Smallest subset (pieces) with statistics; trends need 3 runs. Default 4.
  int min_pieces = 4;
  /// |z| beyond which a score is in the tail. Default 3.
  double tail_z = 3.0;
};

/// Statistics over the pieces with use[j] (all when use is null).
GapSummary ComputeGap(const CampaignData& campaign, const std::vector<Scores>& scores, const GapOptions& options,
                      const std::vector<char>* use = nullptr);

}  // namespace umbmark::diag
