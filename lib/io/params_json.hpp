// Reader for calibrated robot parameters in a `calibrate` JSON (contract:
// `refined.parameters` when present, else `parameters`, with the keys
// wheelbase_m, wheel_diameter_left_m, wheel_diameter_right_m and optional
// ticks_per_rev; a batch result `{"results": [one]}` is accepted).
#pragma once

#include <string>
#include <string_view>

#include "core/robot.hpp"

namespace umbmark::io {

/// Parameters from JSON text; `path` names it in messages and `recorded`
/// supplies what the JSON leaves out. Throws InputError (with line and column
/// for syntax errors) on any fault: invalid JSON, a number out of double
/// range (1e400), a missing or non-numeric key, parameters failing
/// RobotParams::Check().
RobotParams ParseParamsJson(std::string_view text, const std::string& path, const RobotParams& recorded);

/// Same, read from the file `path`.
RobotParams ReadParamsJson(const std::string& path, const RobotParams& recorded);

}  // namespace umbmark::io
