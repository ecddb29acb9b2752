// Robot parameters as the odometry USED them while runs were recorded
// (nominal values or an earlier calibration). Contract: robot file keys
// wheelbase_m, wheel_diameter_left_m, wheel_diameter_right_m, ticks_per_rev.
#pragma once

#include <cmath>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "core/angles.hpp"
#include "core/errors.hpp"

namespace umbmark {

struct RobotParams {
  /// Distance between the wheel contact points [m]. Must be > 0.
  double wheelbase_m = 0.0;
  /// Effective left / right wheel diameters [m]. Must be > 0.
  double wheel_diameter_left_m = 0.0;
  double wheel_diameter_right_m = 0.0;
  /// Encoder ticks per WHEEL revolution (gear ratio included); only needed
  /// when ticks are read. May be fractional (e.g. 43.7 * 64 = 2796.8).
  std::optional<double> ticks_per_rev;

  /// Wheel travel per encoder tick [m/tick] for the left / right wheel.
  /// Precondition: ticks_per_rev is set (checked by CheckTicks()).
  double MetresPerTickLeft() const { return kPi * wheel_diameter_left_m / *ticks_per_rev; }
  double MetresPerTickRight() const { return kPi * wheel_diameter_right_m / *ticks_per_rev; }

  /// Returns an empty string when valid, else a message naming the bad field,
  /// its value and the rule it broke.
  std::string Check() const {
    auto positive = [](const char* name, double v) -> std::string {
      if (!std::isfinite(v) || !(v > 0.0)) return fmt::format("{} = {} must be a finite number > 0", name, v);
      return {};
    };
    if (auto e = positive("wheelbase_m", wheelbase_m); !e.empty()) return e;
    if (auto e = positive("wheel_diameter_left_m", wheel_diameter_left_m); !e.empty()) return e;
    if (auto e = positive("wheel_diameter_right_m", wheel_diameter_right_m); !e.empty()) return e;
    if (ticks_per_rev) {
      if (auto e = positive("ticks_per_rev", *ticks_per_rev); !e.empty()) return e;
    }
    return {};
  }
  std::string CheckTicks() const {
    if (!ticks_per_rev) return "ticks_per_rev is required to convert encoder ticks to wheel travel";
    return Check();
  }
};

}  // namespace umbmark
