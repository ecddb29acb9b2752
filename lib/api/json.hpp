// The JSON building blocks every command's result shares (lib/api): numbers
// that stay valid JSON, robot parameters, the evaluation keys of the
// contract, and the text of a JSON document with invalid UTF-8 escaped.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "core/robot.hpp"
#include "evaluation/trajectory_eval.hpp"

namespace umbmark::api {

/// Round-trips doubles; NaN/Inf become null so the JSON stays valid.
nlohmann::json JsonNumber(double v);

/// {wheelbase_m, wheel_diameter_left_m, wheel_diameter_right_m[, ticks_per_rev]}.
nlohmann::json JsonParams(const RobotParams& p);

/// The contract's evaluation keys: `runs` (per run) and `summary`.
nlohmann::json JsonEvaluationRuns(const EvaluationSummary& s);
nlohmann::json JsonEvaluationSummary(const EvaluationSummary& s);

/// The JSON document in `path` (another command's --json output); a file that
/// is not JSON throws InputError naming the file and the byte offset.
nlohmann::json ReadJsonFile(const std::string& path);

/// `j` as text (pretty when indent >= 0), every string and key with invalid
/// UTF-8 bytes escaped as \xNN, so a run id read from a file never breaks
/// the JSON writer.
std::string DumpJson(const nlohmann::json& j, int indent = 2);

}  // namespace umbmark::api
