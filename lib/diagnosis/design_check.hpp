// Campaign design check, run before the baseline fit: can the manifest's
// experiments determine the baseline model at all? The baseline fits the
// wheel diameter ratio E_d (seen as curvature of straight motion), the
// wheelbase error E_b (seen only in rotation: spot turns, arcs) and the wheel
// noise. A campaign of back_and_forth experiments alone never turns, so E_b
// is undetermined: a fit would return an arbitrary E_b (thousands) and a
// confident, wrong verdict. Such a design is refused with what to add.
#pragma once

#include <string>

#include "core/runs.hpp"

namespace umbmark::diag {

/// Empty when the design can determine the baseline; else the reason and
/// what to add, for an error message.
std::string CampaignDesignProblem(const Manifest& manifest);

}  // namespace umbmark::diag
