// Public API: `umbmark summarize` as one call.
//   api::Summarize(api::SummarizeOptions) -> api::SummarizeResult;
//   api::ToJson(result) is the command's --json document, api::SummarizeCsv
//   its --csv, api::FleetReportHtml its --report page.
#pragma once

#include "api/summarize.hpp"
#include "api/summarize_report.hpp"
#include "calibration/fleet.hpp"
