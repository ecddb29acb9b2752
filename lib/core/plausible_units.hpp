// Plausible ranges of the sizes a user types (robot file, manifest, flags):
// a value far outside what any differential-drive robot or UMBmark test
// has is almost always a unit mix-up (a wheelbase of 200 "m" is 200 mm), so
// it is refused where it is read, naming the key, the value and, when the
// value divided by 1000 is plausible, the millimetre reading.
#pragma once

#include <cmath>
#include <string>
#include <string_view>

#include <fmt/format.h>

namespace umbmark {

struct PlausibleRange {
  std::string_view key;
  double lo, hi;          ///< inclusive bounds
  std::string_view unit;  ///< "m" (a length: the mm hint applies) or a word
};

/// The ranges (docs/safety.md, "Unit mix-ups"). Wide on purpose: a 1 cm
/// micro-robot and a 10 m mining vehicle pass; a value in millimetres does
/// not (the smallest mm wheelbase, 10 mm, reads as 10 m only at the limit).
inline constexpr PlausibleRange kPlausibleRanges[] = {
    {"wheelbase_m", 0.01, 10.0, "m"},
    {"wheel_diameter_left_m", 0.005, 3.0, "m"},
    {"wheel_diameter_right_m", 0.005, 3.0, "m"},
    // Below one tick per wheel revolution nothing is measured; above 1e9 no
    // encoder and gearbox exist (a 24-bit encoder behind 50:1 is 8.4e8).
    {"ticks_per_rev", 1.0, 1e9, "ticks per wheel revolution"},
    {"side_m", 0.05, 100.0, "m"},
    {"distance_m", 0.05, 1000.0, "m"},
};

/// Empty when `value` of `key` lies in its plausible range (or `key` has
/// none), else "KEY = VALUE is outside the plausible range LO to HI UNIT"
/// with a millimetre hint where it fits. VALUE is printed briefly.
inline std::string ImplausibleValue(std::string_view key, double value) {
  for (const auto& r : kPlausibleRanges) {
    if (r.key != key) continue;
    if (std::isfinite(value) && value >= r.lo && value <= r.hi) return {};
    std::string msg = fmt::format("{} = {:.6g} is outside the plausible range {:g} to {:g} {}", key, value, r.lo,
                                  r.hi, r.unit);
    const double as_mm = value / 1000.0;
    if (r.unit == "m" && as_mm >= r.lo && as_mm <= r.hi) {
      msg += fmt::format(": was it given in millimetres ({:.6g} mm = {:.6g} m)?", value, as_mm);
    } else if (r.unit == "m") {
      msg += ": lengths are in metres";
    }
    return msg;
  }
  return {};
}

}  // namespace umbmark
