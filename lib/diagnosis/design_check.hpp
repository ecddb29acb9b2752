// Campaign design check, run before the baseline fit: can the manifest's
// experiments determine the baseline model at all? The baseline fits the
// wheel diameter ratio E_d (seen as curvature of straight motion), the
// wheelbase error E_b (seen only in rotation: spot turns, arcs) and the wheel
// noise. A campaign of back_and_forth experiments alone never turns, so E_b
// is undetermined: a fit would return an arbitrary E_b (thousands) and a
// confident, wrong verdict. Such a design is refused with what to add.
//
// After the fit, what the design cannot tell apart: turn_scrub scales the
// heading change inside spot turns by 1 - k, and on a campaign whose only
// rotation is spot turns (squares, back-and-forth reversals) that is
// exactly a wheelbase b E_b / (1 - k): the ground truth of a scrub and of a
// wheelbase error agree to 1e-9 m, so the fitted E_b absorbs any scrub and
// `none` is the honest verdict. Arcs (a free experiment: figure-eights)
// turn while driving, where a scrub does not act, and separate them.
#pragma once

#include <string>

#include "core/runs.hpp"
#include "diagnosis/pieces.hpp"
#include "effects/effect.hpp"

namespace umbmark::diag {

/// Empty when the design can determine the baseline; else the reason and
/// what to add, for an error message.
std::string CampaignDesignProblem(const Manifest& manifest);

/// What the campaign's design shows for the effects' design notes
/// (effects::Effect::DesignNote): its spot-turn and arc pieces and the
/// baseline's E_b (`separable` is left true: the caller sets it per
/// candidate).
effects::DesignFacts DesignFactsOf(const CampaignData& campaign, double E_b);

}  // namespace umbmark::diag
