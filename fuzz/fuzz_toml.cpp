// libFuzzer target for the TOML readers: the robot file and the campaign
// manifest (from text). Only InputError may escape; accepted robots must pass
// RobotParams::Check() and accepted manifests must hold what the reader
// promises.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "core/errors.hpp"
#include "formats/manifest.hpp"
#include "formats/robot_toml.hpp"

namespace {

void Require(bool ok) {
  if (!ok) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const umbmark::RobotParams robot = umbmark::io::ParseRobotToml(text, "fuzz.toml");
    Require(robot.Check().empty());
  } catch (const umbmark::InputError&) {
  }
  try {
    const umbmark::Manifest m = umbmark::io::ParseManifest(text, "dir/fuzz.toml");
    Require(m.robot.Check().empty() && !m.experiments.empty());
    for (const auto& e : m.experiments) {
      Require(!e.file.empty() && !e.resolved_file.empty());
      if (e.kind == umbmark::ExperimentKind::kSquare) Require(e.side_m > 0.0);
      if (e.kind == umbmark::ExperimentKind::kBackAndForth) Require(e.distance_m > 0.0);
    }
    if (m.ground_truth) Require(m.ground_truth->sigma_xy_m >= 0.0 && m.ground_truth->sigma_theta_rad >= 0.0);
  } catch (const umbmark::InputError&) {
  }
  return 0;
}
