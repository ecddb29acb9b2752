// The campaign's own speeds and distances (effects::CampaignScale), which
// turn an effect's parameter into a pose size for its practical floor
// (docs/diagnosis.md, "Practical floors").
#pragma once

#include "diagnosis/pieces.hpp"
#include "effects/effect.hpp"

namespace umbmark::diag {

/// From the timed runs' nominal wheel travel: the median |v| over the
/// sample intervals of straights and arcs, the median |w| over those of
/// spot turns and arcs (wheelbase from
/// the manifest's robot), and the median travel (|L| + |R|) / 2 of a
/// straight or arc motion between two standstills (a leg). What a campaign lacks (no timed runs, no turns)
/// keeps CampaignScale's default. `negligible`: DiagnoseOptions::negligible.
effects::CampaignScale CampaignScaleOf(const CampaignData& c, double negligible);

}  // namespace umbmark::diag
