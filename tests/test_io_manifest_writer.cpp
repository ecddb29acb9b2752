// The campaign manifest writer (io::FormatManifest) against the reader
// (io::ParseManifest, toml++): every value written reads back bit for bit,
// awkward doubles and file names with quotes, backslashes and control
// characters included; keys keep the contract's order (kind first).
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>
#include <string>

#include "formats/campaign_writer.hpp"
#include "formats/manifest.hpp"
#include "support/bits.hpp"

using namespace umbmark;

namespace {

using test::Bits;

}  // namespace

TEST_CASE("manifest writer: every value reads back bit for bit", "[io][manifest]") {
  // Plausible values (the reader checks ranges) with full 53-bit mantissas.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> factor(0.5, 2.0);
  std::vector<double> factors = {1.0, std::nextafter(1.0, 2.0), 1.0 / 3.0 * 3.0 + 1e-16, 1.1, 0.7777777777777777};
  for (int i = 0; i < 200; ++i) factors.push_back(factor(rng));
  for (double f : factors) {
    INFO(f);
    const double v = 0.2 * f;
    Manifest m;
    m.path = "/tmp/m.toml";
    m.robot.wheelbase_m = v;
    m.robot.wheel_diameter_left_m = 0.084 * f;
    m.robot.wheel_diameter_right_m = std::nextafter(0.084 * f, 1.0);
    m.robot.ticks_per_rev = 2796.8 * f;
    m.ground_truth = GroundTruthNoise{0.0005 * f, 0.0};
    Experiment sq;
    sq.kind = ExperimentKind::kSquare;
    sq.side_m = v;
    sq.file = "a \"quoted\" \\ name\twith\ncontrol\x01.csv";
    Experiment bf;
    bf.kind = ExperimentKind::kBackAndForth;
    bf.distance_m = 10.0 * v;
    bf.file = "fb.csv";
    m.experiments = {sq, bf};
    const std::string text = io::FormatManifest(m, {"written by test_io_manifest_writer"});
    const Manifest back = io::ParseManifest(text, "/tmp/m.toml");
    CHECK(Bits(back.robot.wheelbase_m) == Bits(m.robot.wheelbase_m));
    CHECK(Bits(back.robot.wheel_diameter_left_m) == Bits(m.robot.wheel_diameter_left_m));
    CHECK(Bits(back.robot.wheel_diameter_right_m) == Bits(m.robot.wheel_diameter_right_m));
    REQUIRE(back.robot.ticks_per_rev.has_value());
    CHECK(Bits(*back.robot.ticks_per_rev) == Bits(*m.robot.ticks_per_rev));
    REQUIRE(back.ground_truth.has_value());
    CHECK(Bits(back.ground_truth->sigma_xy_m) == Bits(m.ground_truth->sigma_xy_m));
    CHECK(Bits(back.ground_truth->sigma_theta_rad) == Bits(0.0));
    REQUIRE(back.experiments.size() == 2);
    CHECK(back.experiments[0].kind == ExperimentKind::kSquare);
    CHECK(Bits(back.experiments[0].side_m) == Bits(v));
    CHECK(back.experiments[0].file == sq.file);
    CHECK(back.experiments[1].kind == ExperimentKind::kBackAndForth);
    CHECK(Bits(back.experiments[1].distance_m) == Bits(bf.distance_m));
    // The contract's key order, shortest round-trip digits (0.2, not
    // toml++'s 0.20000000000000001).
    CHECK(text.find("kind = \"square\"\nside_m = ") != std::string::npos);
    if (f == 1.0) CHECK(text.find("wheelbase_m = 0.2\n") != std::string::npos);
  }
}
