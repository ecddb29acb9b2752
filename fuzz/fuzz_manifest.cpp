// libFuzzer target for the campaign manifest (TOML): ParseManifest on the
// bytes. Only InputError may escape; an accepted manifest must hold what the
// reader promises (a valid robot inside the plausible unit ranges, at least
// one experiment, sizes inside their ranges, non-negative ground-truth
// noise), and writing it back (FormatManifest, what simulate and import
// write) must read back to the same values, bit for bit.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "core/errors.hpp"
#include "core/plausible_units.hpp"
#include "formats/campaign_writer.hpp"
#include "formats/manifest.hpp"

namespace {

void Require(bool ok) {
  if (!ok) __builtin_trap();
}

bool SameDouble(double a, double b) { return a == b || (a != a && b != b); }

void CheckAccepted(const umbmark::Manifest& m) {
  using umbmark::ImplausibleValue;
  Require(m.robot.Check().empty() && !m.experiments.empty());
  Require(ImplausibleValue("wheelbase_m", m.robot.wheelbase_m).empty());
  Require(ImplausibleValue("wheel_diameter_left_m", m.robot.wheel_diameter_left_m).empty());
  Require(ImplausibleValue("wheel_diameter_right_m", m.robot.wheel_diameter_right_m).empty());
  if (m.robot.ticks_per_rev) Require(ImplausibleValue("ticks_per_rev", *m.robot.ticks_per_rev).empty());
  for (const auto& e : m.experiments) {
    Require(!e.file.empty() && !e.resolved_file.empty());
    if (e.kind == umbmark::ExperimentKind::kSquare) Require(ImplausibleValue("side_m", e.side_m).empty());
    if (e.kind == umbmark::ExperimentKind::kBackAndForth) Require(ImplausibleValue("distance_m", e.distance_m).empty());
  }
  if (m.ground_truth) Require(m.ground_truth->sigma_xy_m >= 0.0 && m.ground_truth->sigma_theta_rad >= 0.0);
}

void CheckRoundTrip(const umbmark::Manifest& m) {
  const std::string text = umbmark::io::FormatManifest(m);
  umbmark::Manifest back;
  try {
    back = umbmark::io::ParseManifest(text, "dir/fuzz.toml");
  } catch (const umbmark::InputError&) {
    Require(false);  // what we write, we must read
  }
  Require(SameDouble(back.robot.wheelbase_m, m.robot.wheelbase_m) &&
          SameDouble(back.robot.wheel_diameter_left_m, m.robot.wheel_diameter_left_m) &&
          SameDouble(back.robot.wheel_diameter_right_m, m.robot.wheel_diameter_right_m));
  Require(back.robot.ticks_per_rev.has_value() == m.robot.ticks_per_rev.has_value());
  if (m.robot.ticks_per_rev) Require(SameDouble(*back.robot.ticks_per_rev, *m.robot.ticks_per_rev));
  Require(back.ground_truth.has_value() == m.ground_truth.has_value());
  if (m.ground_truth) {
    Require(SameDouble(back.ground_truth->sigma_xy_m, m.ground_truth->sigma_xy_m) &&
            SameDouble(back.ground_truth->sigma_theta_rad, m.ground_truth->sigma_theta_rad));
  }
  Require(back.experiments.size() == m.experiments.size());
  for (std::size_t i = 0; i < m.experiments.size(); ++i) {
    const auto& a = m.experiments[i];
    const auto& b = back.experiments[i];
    Require(a.kind == b.kind && a.file == b.file && SameDouble(a.side_m, b.side_m) &&
            SameDouble(a.distance_m, b.distance_m) && a.resolved_file == b.resolved_file);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  umbmark::Manifest m;
  try {
    m = umbmark::io::ParseManifest(text, "dir/fuzz.toml");
  } catch (const umbmark::InputError&) {
    return 0;
  }
  CheckAccepted(m);
  CheckRoundTrip(m);
  return 0;
}
