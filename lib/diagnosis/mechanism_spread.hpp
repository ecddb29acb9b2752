// A noise effect within the named mechanisms' reach is their spread, not a
// cause of its own (docs/diagnosis.md, "A noise effect within the
// mechanisms' reach"): one of the verdict's filters, after negligible,
// decisive and physical value (diagnose.cpp).
#pragma once

#include "diagnosis/baseline.hpp"
#include "diagnosis/explanation.hpp"
#include "diagnosis/model.hpp"

namespace umbmark::diag {

/// Marks the named noise steps of `ex` that are the named mechanisms'
/// spread (ExplanationStep::spread_of_named; docs/diagnosis.md, "A noise
/// effect within the mechanisms' reach"). A contract mechanism has one
/// value, a real one varies from event to event (a physics engine's turn
/// scrub k = 0.0151 with sd 0.0007 per spot turn; a swivel castor's first
/// kick 6 +- 45 mrad), and that scatter is taken by a noise effect. Call
/// once the verdict's filters (negligible, not_decisive, unphysical,
/// outside_range) are set on ex.steps; `b` gives the values a mechanism's
/// parameters take without it.
void MarkSpreads(const CampaignData& c, const MeanModel& model, const BaselineFit& b, Explanation& ex);

}  // namespace umbmark::diag
