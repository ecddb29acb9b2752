// Where the runs leave the baseline: the gap statistics (gap_stats.hpp)
// ranked by |z|, with the experiment and subset each describes.
#pragma once

#include <string>
#include <vector>

#include "diagnosis/gap_stats.hpp"
#include "diagnosis/pieces.hpp"

namespace umbmark::diag {

/// One localised discrepancy.
struct WhereItem {
  int experiment = 0;  ///< 0-based
  std::string subset;
  StatKind statistic = StatKind::kMean;
  std::string component;  ///< heading, along-track, lateral, or "a x b" for correlations
  double z = 0.0;
  int n = 0;
};

/// The `top` largest discrepancies of `gap`, largest first.
std::vector<WhereItem> LocateGap(const CampaignData& c, const GapSummary& gap, int top);

}  // namespace umbmark::diag
