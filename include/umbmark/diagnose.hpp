// Public facade: why a robot's real runs differ from its simulation.
//   api::Diagnose(api::DiagnoseOptions) -> api::DiagnoseResult: `umbmark
//   diagnose` as one call; api::ToJson(result) is its JSON.
//   diag::LoadCampaign(manifest path) -> CampaignData;
//   diag::Diagnose(campaign, options) -> DiagnoseSummary;
//   diag::DiagnoseToJson, diag::DiagnoseReport; api::DiagnosePlotsSvg and
//   api::DiagnoseReportHtml draw the --plot and --report from the JSON.
#pragma once

#include "api/diagnose.hpp"
#include "diagnosis/diagnose.hpp"
#include "api/diagnose_report.hpp"
#include "diagnosis/pieces.hpp"
#include "umbmark/io.hpp"
