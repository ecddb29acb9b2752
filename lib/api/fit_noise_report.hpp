// The figure, HTML page and shared sentences of `umbmark fit-noise` from a
// FitNoiseResult (fit_noise.hpp).
#pragma once

#include <string>
#include <vector>

#include "api/fit_noise.hpp"

namespace umbmark::api {

/// Figure 4 of Chong & Kleeman, per group: each run's return error, and for
/// each group (experiment and direction) its observed 95 % ellipse (solid)
/// and the fitted model's (dashed), both about the group's own systematic
/// mean; for ex-ey, ex-etheta, ey-etheta: the --plot SVG.
std::string FitNoisePlotSvg(const FitNoiseResult& result);

/// The --report page: headline, next steps, warnings and notes (the
/// result's), the group means, the goodness of fit and `svg`
/// (FitNoisePlotSvg). `inputs`: what the command was given.
std::string FitNoiseReportHtml(const FitNoiseResult& result, const std::vector<std::string>& inputs,
                               const std::string& svg);

/// Which experiment would determine an undetermined k (`name` is "k_L" or
/// "k_R"), as a clause.
std::string DetermineKExperiment(const FitNoiseResult& f, const std::string& name);

/// What bounds an undetermined k: "only bounded: k_L < x m^1/2 at 95 %", or
/// that the profile likelihood never falls far enough.
std::string KBound(const std::string& name, double upper);

/// The warning for an undetermined k: what bounds it and what would
/// determine it (JSON, text and HTML).
std::string UndeterminedK(const FitNoiseResult& f, const std::string& name);

}  // namespace umbmark::api
