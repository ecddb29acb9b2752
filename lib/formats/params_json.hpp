// Reader for calibrated robot parameters in a `calibrate` JSON (contract:
// `refined.parameters` when present, else `parameters`, with the keys
// wheelbase_m, wheel_diameter_left_m, wheel_diameter_right_m and optional
// ticks_per_rev; a batch result `{"results": [one]}` is accepted).
#pragma once

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "core/robot.hpp"

namespace umbmark::io {

/// A whole JSON document. Throws InputError naming `path`, with line and
/// column, for a syntax error and for a number beyond double range (1e400,
/// which nlohmann reports without a position).
nlohmann::json ParseJsonDocument(std::string_view text, const std::string& path);

/// Empty when `p`'s wheelbase and diameters lie in their plausible ranges
/// (core/plausible_units.hpp), else the message naming the first bad one:
/// a calibration JSON may hold anything (-0.2, 1e308).
std::string ImplausibleParams(const RobotParams& p);

/// Parameters from JSON text; `path` names it in messages and `recorded`
/// supplies what the JSON leaves out. Throws InputError (with line and column
/// for syntax errors) on any fault: invalid JSON, a number out of double
/// range (1e400), a missing or non-numeric key, parameters failing
/// RobotParams::Check() or outside their plausible ranges (1e308 m).
RobotParams ParseParamsJson(std::string_view text, const std::string& path, const RobotParams& recorded);

/// Same, read from the file `path`.
RobotParams ReadParamsJson(const std::string& path, const RobotParams& recorded);

}  // namespace umbmark::io
