// Public facade: why a robot's real runs differ from its simulation.
//   diag::LoadCampaign(manifest path) -> CampaignData;
//   diag::Diagnose(campaign, options) -> DiagnoseSummary;
//   diag::DiagnoseToJson, diag::DiagnoseReport.
#pragma once

#include "diagnosis/diagnose.hpp"
#include "diagnosis/pieces.hpp"
#include "umbmark/io.hpp"
