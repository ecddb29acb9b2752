// Whether a fitted effect is physically possible: a negative turn scrub, a
// wheel-noise correlation at +-1 or a castor kick of several degrees is
// not a cause but a symptom (the effect soaked up something else). Used by
// the candidates' likelihood-ratio tests (an impossible fit is not
// evidence), the explanation's naming and the report. Each effect's rule
// is in its own file (lib/effects/<name>.cpp).
#pragma once

#include <map>
#include <string>

namespace umbmark::diag {

/// Why a fitted effect is physically impossible or implausible (empty when
/// it is not): a negative or >= 1 turn scrub, a correlation at +-1, a wheel
/// diameter off by more than 10 %, a castor kick over 50 mrad (3 deg), a
/// ground-truth marker more than 0.3 m off the axle, a right wheel
/// drifting by more than 5 % over the campaign (`runs`), noise of more
/// than 50 mm per event, run time offsets over 1 s. A turn scrub counts as
/// negative below -0.01, or below 0 by more than 2 of its standard errors
/// (`se`, when given). Such a fit is a symptom: the effect soaked up
/// something else.
std::string UnphysicalFit(const std::string& effect, const std::map<std::string, double>& params, int runs,
                          const std::map<std::string, double>& se = {});

/// Why a noise effect fitted at zero is no explanation (empty otherwise):
/// every variance it adds is below a micrometre, a microradian, 10 us of
/// clock or a correlation of 1e-4, so what its fit gains (the other noise
/// parameters refitted beside it) is not its own. Mean effects and the
/// given model's wheel_noise_error (a k of 0 is a finding) are never null.
std::string NullNoiseFit(const std::string& effect, const std::map<std::string, double>& params);

}  // namespace umbmark::diag
