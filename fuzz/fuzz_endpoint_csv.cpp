// libFuzzer target for the endpoint CSV (return errors) and what calibrate
// does with it: ParseEndpointCsv on the bytes; only InputError may escape.
// Accepted data must satisfy the reader's guarantees, write back
// (FormatEndpointCsv, what simulate and import write) to the same numbers,
// and go through the calibrate pipeline's data checks, UMBmark and the
// plausibility gates without a crash; a result the gates pass must be
// finite with multipliers inside (0.5, 2) and positive parameters.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "calibration/plausibility.hpp"
#include "calibration/umbmark.hpp"
#include "core/angles.hpp"
#include "core/errors.hpp"
#include "formats/campaign_writer.hpp"
#include "formats/endpoint_csv.hpp"

namespace {

void Require(bool ok) {
  if (!ok) __builtin_trap();
}

bool PlainId(const std::string& s) {
  for (const char c : s)
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-'))
      return false;
  return !s.empty();
}

void CheckRoundTrip(const umbmark::EndpointData& d) {
  for (const auto& r : d.runs)
    if (!PlainId(r.run) || !PlainId(r.direction)) return;  // cells the writer cleans: not comparable
  umbmark::EndpointData back;
  try {
    back = umbmark::io::ParseEndpointCsv(umbmark::io::FormatEndpointCsv(d), "back.csv");
  } catch (const umbmark::InputError&) {
    Require(false);  // what we write, we must read
  }
  Require(back.runs.size() == d.runs.size());
  for (std::size_t i = 0; i < d.runs.size(); ++i) {
    const auto& a = d.runs[i];
    const auto& b = back.runs[i];
    Require(a.run == b.run && a.direction == b.direction && a.ex_m == b.ex_m && a.ey_m == b.ey_m);
    Require(a.etheta_rad.has_value() == b.etheta_rad.has_value());
    if (a.etheta_rad) Require(*a.etheta_rad == *b.etheta_rad);
  }
}

void CheckCalibration(const umbmark::EndpointData& d, double side_m) {
  umbmark::RobotParams robot;
  robot.wheelbase_m = 0.34;
  robot.wheel_diameter_left_m = robot.wheel_diameter_right_m = 0.1524;
  if (!umbmark::CheckReturnErrorScale(d.runs, side_m).empty()) return;  // refused before the fit (exit 1)
  umbmark::UmbmarkOptions o;
  o.side_m = side_m;
  umbmark::UmbmarkSummary s;
  try {
    s = umbmark::CalibrateUmbmark(d.runs, robot, o, "fuzz.csv");
  } catch (const umbmark::InputError&) {
    return;  // no cw or ccw runs, unknown direction: exit 1
  }
  const umbmark::PlausibilityReport r = umbmark::CheckUmbmarkPlausibility(s);
  if (!r.ok()) {
    Require(!r.Message().empty());
    return;
  }
  const auto& e = s.selected;
  for (const double v : {e.E_b, e.E_d, e.alpha_rad, e.beta_rad, s.E_max_syst_m, s.c_L, s.c_R})
    Require(std::isfinite(v));
  Require(e.E_b > umbmark::kMinMultiplier && e.E_b < umbmark::kMaxMultiplier);
  Require(s.corrected.wheelbase_m > 0.0 && s.corrected.wheel_diameter_left_m > 0.0 &&
          s.corrected.wheel_diameter_right_m > 0.0);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  umbmark::EndpointData d;
  try {
    d = umbmark::io::ParseEndpointCsv(text, "fuzz.csv");
  } catch (const umbmark::InputError&) {
    return 0;
  }
  Require(!d.runs.empty());
  for (const auto& r : d.runs) {
    Require(!r.run.empty() && !r.direction.empty());
    Require(std::isfinite(r.ex_m) && std::isfinite(r.ey_m));
    if (r.etheta_rad) Require(*r.etheta_rad > -umbmark::kPi && *r.etheta_rad <= umbmark::kPi);
  }
  CheckRoundTrip(d);
  // The side from the input's first byte: 0.05 m (the smallest plausible) to 100 m.
  const double side = size > 0 ? 0.05 * std::pow(2000.0, data[0] / 255.0) : 4.0;
  CheckCalibration(d, side);
  return 0;
}
