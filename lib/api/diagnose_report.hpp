// The plots and the --report page of `umbmark diagnose`, drawn from its JSON (the
// documented keys: gap.where, candidates, explanation, verdict), so they
// show whatever the diagnosis provides.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace umbmark::api {

/// Standardised discrepancies against the model's 95% band (largest
/// marked), held-out shrink per candidate, cumulative shrink of the
/// explanation when present.
std::string DiagnosePlotsSvg(const nlohmann::json& j);
/// The self-contained HTML page (verdict, what to do next, tables, plots).
std::string DiagnoseReportHtml(const nlohmann::json& j, const std::string& manifest);

}  // namespace umbmark::api
