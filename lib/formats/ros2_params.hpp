// ROS 2 parameter files for ros2_control's diff_drive_controller, in the
// format `ros2 param load` and the controller manager's --param-file read:
//   <controller>:
//     ros__parameters:
//       <name>: <value>
// Comments carry the provenance and the robot parameters the multipliers
// refer to. Values are written in shortest round-trip form.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/robot.hpp"

namespace umbmark::io {

/// Calibration result as diff_drive_controller multipliers, each relative to
/// the parameter the runs were recorded with.
struct DiffDriveMultipliers {
  double wheel_separation_multiplier = 1.0;
  double left_wheel_radius_multiplier = 1.0;
  double right_wheel_radius_multiplier = 1.0;
};

/// YAML text with the three multipliers; the recorded robot's
/// wheel_separation and wheel_radius (per wheel) go in comments, with
/// `comment` lines (provenance) first. Throws InvalidOptions for an empty or
/// non-identifier controller name.
std::string FormatDiffDriveCalibration(const std::string& controller, const DiffDriveMultipliers& m,
                                       const RobotParams& recorded, const std::vector<std::string>& comment);

/// YAML text with pose_covariance_diagonal and twist_covariance_diagonal
/// (x, y, z, roll, pitch, yaw order).
std::string FormatDiffDriveCovariance(const std::string& controller, const std::array<double, 6>& pose_diagonal,
                                      const std::array<double, 6>& twist_diagonal, const std::vector<std::string>& comment);

}  // namespace umbmark::io
