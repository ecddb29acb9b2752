// Where a command's robot parameters come from (lib/api): a robot file
// and/or per-field overrides, on top of a manifest's [robot]. The command
// line's --robot, --wheelbase, --diameter-left, --diameter-right,
// --ticks-per-rev.
#pragma once

#include <optional>
#include <string>

#include "core/robot.hpp"

namespace umbmark::api {

struct RobotSource {
  /// [--robot] robot file (TOML): the parameters the odometry USED. "" = none.
  std::string robot_file;
  /// [--wheelbase, --diameter-left, --diameter-right, --ticks-per-rev]
  /// overrides of single fields; unset = from the file or the manifest.
  std::optional<double> wheelbase_m, diameter_left_m, diameter_right_m, ticks_per_rev;

  /// A file or any override is given.
  bool Given() const;
  /// "" when every given override is a finite number > 0 in its plausible
  /// range (core/plausible_units.hpp), else a message naming the flag.
  std::string Check() const;
  /// Robot from the file (if any) with the overrides applied, on top of
  /// `base` (e.g. a manifest's [robot]). Throws InputError for a bad file,
  /// InvalidOptions when the result fails RobotParams::Check() or a required
  /// field is missing everywhere.
  RobotParams Resolve(const std::optional<RobotParams>& base = std::nullopt) const;
};

/// "--FLAG: must be a finite number > 0 (got 'V')" or the plausible-range
/// message of `key` (as the command line's validators say it); "" when fine.
std::string CheckPlausibleFlag(const char* flag, const char* key, double value);

}  // namespace umbmark::api
