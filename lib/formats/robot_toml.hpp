// Reader for the contract's robot file (TOML), also used for the [robot]
// table of a campaign manifest:
//   wheelbase_m = 0.340
//   wheel_diameter_left_m = 0.1524
//   wheel_diameter_right_m = 0.1524
//   ticks_per_rev = 2048          # optional unless ticks are read
#pragma once

#include <string>
#include <string_view>

#include "core/robot.hpp"

namespace toml {
inline namespace v3 {
class table;
}
}  // namespace toml

namespace umbmark::io {

/// Throws InputError (file, line, column) for a TOML syntax error, a missing
/// or non-numeric key, an unknown key, or a value that fails RobotParams::Check().
/// A campaign manifest (a [robot] table and [[experiment]]s) gives its robot.
RobotParams ReadRobotToml(const std::string& path);
RobotParams ParseRobotToml(std::string_view text, const std::string& name);

/// Reads robot keys from an already-parsed table (the manifest's [robot]).
RobotParams RobotFromTable(const toml::table& table, const std::string& name);

}  // namespace umbmark::io
