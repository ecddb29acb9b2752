// Stage "null distribution" of the diagnosis: what the gap score G looks like
// when the data come from the fitted baseline itself. A parametric bootstrap
// simulates `simulations` campaigns of piece residuals from the baseline's
// noise model (wheel noise per piece, ground-truth noise per boundary sample
// shared by neighbouring pieces, encoder quantisation), refits E_d, E_b
// (linearised) and the noise like the data, and scores each (gap_stats.hpp).
#pragma once

#include <cstdint>
#include <vector>

#include "core/progress.hpp"
#include "diagnosis/baseline.hpp"
#include "diagnosis/gap_stats.hpp"

namespace umbmark::diag {

struct NullOptions {
  /// Simulated campaigns (>= 20). Default 500.
  int simulations = 500;
  /// The reported quantile is 1 - alpha. Default 0.01.
  double alpha = 0.01;
  /// Seed of the simulations (replicate r uses stream r). Default 1.
  std::uint64_t seed = 1;
  /// Threads (>= 1); the result does not depend on them. Default 2.
  int threads = 2;
  GapOptions gap;
  /// Progress in simulated campaigns (core/progress.hpp). Default: none.
  ProgressCallback progress;
};

struct NullDistribution {
  std::vector<double> sorted;   ///< G of every simulated campaign, ascending
  double median = 0.0;          ///< G0: what the model's own noise produces
  double quantile_alpha = 0.0;  ///< G at the 1 - alpha quantile
};

NullDistribution SimulateNullDistribution(const CampaignData& c, const MeanModel& model, const BaselineFit& baseline,
                                          const NullOptions& options);

/// p-value of `g` against the sorted null sample: the empirical tail
/// (1 + #{G* >= g}) / (1 + B) while at least 10 simulations reach g; beyond
/// that an exponential tail fitted to the excesses over the null's 80 %
/// quantile (peaks over threshold with shape 0: G is a sum of squared
/// excesses, whose tail decays like a gamma's), so significance does not
/// depend on B being large.
double NullPValue(const std::vector<double>& sorted, double g);

}  // namespace umbmark::diag
