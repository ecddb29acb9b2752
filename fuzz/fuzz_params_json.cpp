// libFuzzer target for the calibrated-parameters JSON reader (`evaluate
// --params CAL.json`). Only InputError may escape; accepted parameters must
// pass RobotParams::Check() (finite, positive lengths).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/errors.hpp"
#include "formats/params_json.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  umbmark::RobotParams recorded;
  recorded.wheelbase_m = 0.34;
  recorded.wheel_diameter_left_m = recorded.wheel_diameter_right_m = 0.1524;
  recorded.ticks_per_rev = 2048.0;
  try {
    const umbmark::RobotParams p = umbmark::io::ParseParamsJson(text, "fuzz.json", recorded);
    if (!p.Check().empty()) __builtin_trap();
  } catch (const umbmark::InputError&) {
  }
  return 0;
}
