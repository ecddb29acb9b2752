// Where the runs leave the baseline (see where.hpp).
#include "diagnosis/where.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace umbmark::diag {

namespace {

std::string WhereComponent(const GapStatistic& s) {
  if (s.kind == StatKind::kCorrelation) return fmt::format("{} x {}", ComponentName(s.comp_a), ComponentName(s.comp_b));
  return ComponentName(s.comp_a);
}

}  // namespace

std::vector<WhereItem> LocateGap(const CampaignData& c, const GapSummary& gap, int top) {
  std::vector<WhereItem> where;
  std::vector<GapStatistic> sorted = gap.stats;
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return std::abs(a.z) > std::abs(b.z); });
  for (std::size_t i = 0; i < sorted.size() && static_cast<int>(i) < top; ++i) {
    const GapStatistic& s = sorted[i];
    WhereItem w;
    w.experiment = c.subsets[s.subset].experiment;
    w.subset = c.subsets[s.subset].name;
    if (s.kind == StatKind::kTrend) w.subset += " (early vs late runs)";
    w.statistic = s.kind;
    w.component = WhereComponent(s);
    w.z = s.z;
    w.n = s.n;
    where.push_back(w);
  }
  return where;
}

}  // namespace umbmark::diag
