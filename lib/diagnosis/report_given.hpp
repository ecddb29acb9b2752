// Output of `diagnose --baseline` (baseline_given.hpp) beside the default
// report: the given model ("baseline.given") and what to change in the
// user's simulation ("corrections") in the JSON, and the matching text.
#pragma once

#include <string>

#include <nlohmann/json_fwd.hpp>

namespace umbmark::diag {

struct DiagnoseSummary;

/// Adds "baseline.given" and "corrections" (empty list without a given model)
/// to the diagnosis JSON.
void AddGivenModelJson(const DiagnoseSummary& s, nlohmann::json& j);

/// Text lines on the given model and its corrections (empty without one).
std::string GivenModelReport(const DiagnoseSummary& s);

}  // namespace umbmark::diag
