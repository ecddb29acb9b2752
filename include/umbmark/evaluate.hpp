// Public API: `umbmark evaluate` as one call.
//   api::Evaluate(api::EvaluateOptions) -> api::EvaluateResult;
//   api::ToJson(result) is the command's --json document;
//   api::EvaluatePlotSvg, api::EvaluateReportHtml its --plot and --report.
#pragma once

#include "api/evaluate.hpp"
#include "api/evaluate_report.hpp"
#include "umbmark/io.hpp"
