// `diagnose --baseline CAL.json` from another robot than the campaign's
// (issue 23): refused (exit 1, naming the file and both robots) unless
// --baseline-other-robot; the robot's own calibration, a simulation model
// near it and a second-pass calibration (recorded with the corrected
// parameters) are accepted.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "support/run_cli.hpp"

namespace fs = std::filesystem;
using umbmark::testing::Q;
using umbmark::testing::RunCli;

namespace {

/// A calibrate-like JSON: corrected parameters and, when `recorded_b` > 0,
/// the recorded ones (diameters 0.08 m).
void WriteCal(const fs::path& p, double b, double d, double recorded_b) {
  nlohmann::json j = {{"parameters", {{"wheelbase_m", b}, {"wheel_diameter_left_m", d}, {"wheel_diameter_right_m", d}}}};
  if (recorded_b > 0)
    j["recorded_parameters"] = {{"wheelbase_m", recorded_b}, {"wheel_diameter_left_m", 0.08}, {"wheel_diameter_right_m", 0.08}};
  std::ofstream(p) << j.dump(2);
}

}  // namespace

TEST_CASE("diagnose --baseline refuses another robot's calibration unless asked", "[diagnose][baseline][cli]") {
  const fs::path dir = umbmark::testing::TempDir("baseline-robot");
  std::ofstream(dir / "m.toml") << "[robot]\nwheelbase_m = 0.3\nwheel_diameter_left_m = 0.08\n"
                                   "wheel_diameter_right_m = 0.08\nticks_per_rev = 2000\n\n[[experiment]]\n"
                                   "kind = \"square\"\nside_m = 1.0\nfile = \"sq.csv\"\n";
  REQUIRE(RunCli("simulate " + Q(dir / "m.toml") + " --out " + Q(dir / "sim") + " --square-runs 4 --seed 5").status == 0);
  const std::string diagnose = "diagnose " + Q(dir / "sim" / "campaign.toml") + " --null-sims 20 --json " +
                               Q(dir / "d.json") + " --baseline ";

  // 30 % other wheelbase, no recorded parameters (a hand-written model).
  WriteCal(dir / "wide.json", 0.39, 0.08, 0);
  auto r = RunCli(diagnose + Q(dir / "wide.json"));
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::Contains("wide.json") && Catch::Contains("another robot's") &&
                        Catch::Contains("30.0 %") && Catch::Contains("--baseline-other-robot"));
  CHECK_FALSE(fs::exists(dir / "d.json"));
  // Another robot's calibrate output: recorded with 0.31 m, corrected 0.312 m (4 % off the campaign's 0.3 m).
  WriteCal(dir / "other.json", 0.312, 0.0801, 0.31);
  r = RunCli(diagnose + Q(dir / "other.json"));
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::Contains("recorded_parameters") && Catch::Contains("wheelbase 0.31 m"));
  // Asked for on purpose: it runs.
  r = RunCli(diagnose + Q(dir / "wide.json") + " --baseline-other-robot");
  CHECK(r.status == 0);
  CHECK(fs::exists(dir / "d.json"));
  // The flag alone is a usage error.
  CHECK(RunCli("diagnose " + Q(dir / "sim" / "campaign.toml") + " --baseline-other-robot").status == 2);

  // Accepted: this robot's calibration (recorded 0.3 m, corrected 1 % longer) ...
  WriteCal(dir / "own.json", 0.303, 0.0802, 0.3);
  CHECK(RunCli(diagnose + Q(dir / "own.json")).status == 0);
  // ... and a first-pass calibration whose result is the campaign's robot (second pass on a compensated robot).
  WriteCal(dir / "first_pass.json", 0.3, 0.08, 0.29);
  CHECK(RunCli(diagnose + Q(dir / "first_pass.json")).status == 0);
}
