// The robot's id in a robot file or a manifest's [robot] table:
//   robot_id = "R-0042"   # optional: the robot's serial number or asset tag
// 1-64 bytes of text without control characters. The robot-file readers
// (robot_toml.hpp) check it at its value (InputError, line and column) but
// do not keep it in RobotParams; calibrate reads it here for its JSON.
#pragma once

#include <string>

namespace umbmark::io {

/// The robot_id of the robot file or manifest `path`, or "" when it has none.
/// Throws InputError as ReadRobotToml does.
std::string ReadRobotId(const std::string& path);

}  // namespace umbmark::io
