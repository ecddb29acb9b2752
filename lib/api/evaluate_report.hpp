// The figure and HTML page of `umbmark evaluate --plot/--report` from an
// EvaluateResult (evaluate.hpp) whose options kept the plot runs.
#pragma once

#include <string>
#include <vector>

#include "api/evaluate.hpp"

namespace umbmark::api {

/// Position and heading error along the travelled distance for every kept
/// run (recorded parameters vs --params, one common scale), the 8 runs with
/// the largest final position error (with --params when given) bold and
/// numbered, then their paths, worst first: the --plot SVG.
std::string EvaluatePlotSvg(const EvaluateResult& result);

/// The --report page: headline, next steps, the summary and per-run tables,
/// and `svg` (EvaluatePlotSvg). `inputs` and `params_file` name what was
/// evaluated (the options').
std::string EvaluateReportHtml(const EvaluateResult& result, const std::vector<std::string>& inputs,
                               const std::string& params_file, const std::string& svg);

}  // namespace umbmark::api
