// Robot parameters from a file and overrides (see robot_source.hpp).
#include "api/robot_source.hpp"

#include <cmath>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "core/plausible_units.hpp"
#include "formats/robot_toml.hpp"

namespace umbmark::api {

std::string CheckPlausibleFlag(const char* flag, const char* key, double value) {
  if (!(std::isfinite(value) && value > 0.0)) return fmt::format("{}: must be a finite number > 0 (got '{}')", flag, value);
  if (std::string why = ImplausibleValue(key, value); !why.empty()) return fmt::format("{}: {}", flag, why);
  return {};
}

bool RobotSource::Given() const {
  return !robot_file.empty() || wheelbase_m || diameter_left_m || diameter_right_m || ticks_per_rev;
}

std::string RobotSource::Check() const {
  const struct {
    const char* flag;
    const char* key;
    const std::optional<double>& value;
  } fields[] = {{"--wheelbase", "wheelbase_m", wheelbase_m},
                {"--diameter-left", "wheel_diameter_left_m", diameter_left_m},
                {"--diameter-right", "wheel_diameter_right_m", diameter_right_m},
                {"--ticks-per-rev", "ticks_per_rev", ticks_per_rev}};
  for (const auto& f : fields) {
    if (!f.value) continue;
    if (std::string err = CheckPlausibleFlag(f.flag, f.key, *f.value); !err.empty()) return err;
  }
  return {};
}

RobotParams RobotSource::Resolve(const std::optional<RobotParams>& base) const {
  RobotParams p;
  bool have_file = false;
  if (!robot_file.empty()) {
    p = io::ReadRobotToml(robot_file);
    have_file = true;
  } else if (base) {
    p = *base;
    have_file = true;
  }
  if (wheelbase_m) p.wheelbase_m = *wheelbase_m;
  if (diameter_left_m) p.wheel_diameter_left_m = *diameter_left_m;
  if (diameter_right_m) p.wheel_diameter_right_m = *diameter_right_m;
  if (ticks_per_rev) p.ticks_per_rev = *ticks_per_rev;
  if (!have_file && !(wheelbase_m && diameter_left_m && diameter_right_m)) {
    throw InvalidOptions(
        "robot parameters missing: give --robot R.toml, a campaign manifest, or all of "
        "--wheelbase, --diameter-left, --diameter-right");
  }
  if (auto err = p.Check(); !err.empty()) throw InvalidOptions("robot: " + err);
  return p;
}

}  // namespace umbmark::api
