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

namespace umbmark::diag {

/// Empty when the design can determine the baseline; else the reason and
/// what to add, for an error message.
std::string CampaignDesignProblem(const Manifest& manifest);

/// A note for the report when the campaign rotates only on the spot (turn
/// pieces, no arc pieces) and turn_scrub is therefore not separately
/// identifiable (`scrub_separable` false: the candidate is not, or only
/// weakly, identifiable): that a turn scrub, if any, is inside the fitted
/// wheelbase E_b (`E_b`) and which run to add. Empty otherwise. (Diagnose
/// leaves it out when a weakly identifiable scrub is named on its own
/// held-out evidence: the spot turns' small forward motion, E_d far from 1.)
std::string TurnScrubDesignNote(const CampaignData& campaign, bool scrub_separable, double E_b);

}  // namespace umbmark::diag
