// Property tests over random valid inputs (fixed seeds, so failures
// reproduce): whenever a command exits 0, every number in its JSON is finite
// (no null where a number belongs, no inf/nan) and the corrected parameters
// are positive; otherwise it exits 1 or 3 with a message, never anything else.
// Random byte mutations of valid files never crash a command (exit <= 3).
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "model/commanded_square.hpp"
#include "model/true_robot.hpp"
#include "support/run_cli.hpp"

namespace fs = std::filesystem;
using umbmark::testing::Q;
using umbmark::testing::RunCli;

namespace {

/// Keys whose value may be null by definition (R = infinity when beta = 0,
/// scores and headings that are absent, a model check or a held-out
/// comparison that too few runs cannot give).
const std::set<std::string> kNullable = {"R_m", "outlier_score", "etheta_rad", "model_check", "recommended"};

bool Nullable(const std::string& where, const std::string& key) {
  return kNullable.count(key) == 1 || where.find(".heldout") != std::string::npos;
}

/// Fails on a null outside kNullable or a non-finite number anywhere.
void CheckFinite(const nlohmann::json& j, const std::string& where) {
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) {
      if (it.value().is_null()) {
        INFO(where << "." << it.key());
        CHECK(Nullable(where, it.key()));
      } else {
        CheckFinite(it.value(), where + "." + it.key());
      }
    }
  } else if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i) {
      INFO(where << "[" << i << "]");
      CHECK_FALSE(j[i].is_null());
      CheckFinite(j[i], where + "[" + std::to_string(i) + "]");
    }
  } else if (j.is_number_float()) {
    INFO(where);
    CHECK(std::isfinite(j.get<double>()));
  }
}

void Put(const fs::path& p, const std::string& s) { std::ofstream(p, std::ios::binary) << s; }

}  // namespace

TEST_CASE("property: calibrate on random valid endpoint data never prints a non-finite number", "[safety][property]") {
  std::mt19937_64 rng(20261124);
  const fs::path dir = umbmark::testing::TempDir("prop-cal");
  Put(dir / "robot.toml", "wheelbase_m = 0.34\nwheel_diameter_left_m = 0.1524\nwheel_diameter_right_m = 0.1524\n");
  int ok = 0, refused = 0;
  for (int trial = 0; trial < 40; ++trial) {
    std::uniform_int_distribution<int> runs(1, 8);
    std::uniform_real_distribution<double> log_scale(-6.0, 0.0), unit(-1.0, 1.0), log_side(-1.0, 1.3);
    const double side = std::pow(10.0, log_side(rng));
    const double scale = std::pow(10.0, log_scale(rng)) * side;
    std::string csv = "run,direction,ex_m,ey_m,etheta_rad\n";
    const int n = runs(rng);
    const double cx = unit(rng) * scale, cy = unit(rng) * scale, dx = unit(rng) * scale, dy = unit(rng) * scale;
    for (int i = 0; i < 2 * n; ++i) {
      const bool cw = i % 2 == 0;
      csv += fmt::format("{},{},{},{},{}\n", i + 1, cw ? "cw" : "ccw", (cw ? cx : dx) + 0.1 * scale * unit(rng),
                         (cw ? cy : dy) + 0.1 * scale * unit(rng), 0.01 * unit(rng));
    }
    Put(dir / "ep.csv", csv);
    const auto r = RunCli("calibrate " + Q(dir / "ep.csv") + " --robot " + Q(dir / "robot.toml") +
                          fmt::format(" --side {} --json -", side));
    INFO("trial " << trial << ", side " << side << ", scale " << scale << "\n" << csv << r.err);
    REQUIRE((r.status == 0 || r.status == 1 || r.status == 3));
    if (r.status != 0) {
      CHECK_FALSE(r.err.empty());
      ++refused;
      continue;
    }
    ++ok;
    const auto j = nlohmann::json::parse(r.out);
    CheckFinite(j, "calibrate");
    CHECK(j["parameters"]["wheelbase_m"].get<double>() > 0.0);
    CHECK(j["parameters"]["wheel_diameter_left_m"].get<double>() > 0.0);
    CHECK(j["parameters"]["wheel_diameter_right_m"].get<double>() > 0.0);
    CHECK(j.contains("warnings"));
  }
  // Most random campaigns are plausible; the gates refuse the wild ones.
  CHECK(ok >= 20);
  INFO("refused " << refused);
}

TEST_CASE("property: predict on random valid paths never prints a non-finite number", "[safety][property]") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> len(-1e4, 1e4), angle(-20.0, 20.0), k(0.0, 0.05);
  for (int trial = 0; trial < 25; ++trial) {
    std::string path;
    const int segments = 1 + static_cast<int>(rng() % 5);
    for (int s = 0; s < segments; ++s) {
      if (!path.empty()) path += ",";
      switch (rng() % 3) {
        case 0: path += fmt::format("line:{}", len(rng)); break;
        case 1: path += fmt::format("turn:{}", angle(rng)); break;
        default: path += fmt::format("arc:{}:{}", len(rng), len(rng)); break;
      }
    }
    const auto r = RunCli(fmt::format("predict --wheelbase 0.34 --diameter-left 0.15 --diameter-right 0.15 "
                                      "--kl {} --kr {} --path {} --json -",
                                      k(rng), k(rng), path));
    INFO("trial " << trial << ": " << path << "\n" << r.err);
    REQUIRE((r.status == 0 || r.status == 1 || r.status == 2 || r.status == 3));
    if (r.status == 0) CheckFinite(nlohmann::json::parse(r.out), "predict");
  }
}

TEST_CASE("property: random byte mutations of valid files never crash a command", "[safety][property]") {
  std::mt19937_64 rng(99);
  const fs::path src = fs::path(UMBMARK_SOURCE_DIR);
  const std::string endpoints = umbmark::testing::Slurp((src / "data/examples/endpoints.csv").string());
  const std::string robot = umbmark::testing::Slurp((src / "data/examples/robot.toml").string());
  const fs::path dir = umbmark::testing::TempDir("prop-mut");
  for (int trial = 0; trial < 40; ++trial) {
    std::string e = endpoints, t = robot;
    std::string& victim = trial % 3 == 0 ? t : e;
    const int edits = 1 + static_cast<int>(rng() % 8);
    for (int m = 0; m < edits && !victim.empty(); ++m) {
      const std::size_t at = rng() % victim.size();
      switch (rng() % 3) {
        case 0: victim[at] = static_cast<char>(rng() % 256); break;
        case 1: victim.erase(at, 1 + rng() % 4); break;
        default: victim.insert(at, 1, static_cast<char>(rng() % 256)); break;
      }
    }
    Put(dir / "ep.csv", e);
    Put(dir / "robot.toml", t);
    const auto r = RunCli("calibrate " + Q(dir / "ep.csv") + " --robot " + Q(dir / "robot.toml") + " --side 4 --json -");
    INFO("trial " << trial << "\n" << r.err);
    CHECK((r.status >= 0 && r.status <= 3));
    if (r.status == 0) CheckFinite(nlohmann::json::parse(r.out), "calibrate");
    if (r.status != 0) CHECK_FALSE(r.err.empty());
  }
}

TEST_CASE("property: random unit mix-ups and reversed labels are never calibrated (exit 0)", "[safety][property]") {
  // A realistic campaign (exact commanded squares, E_b 1 +- 0.5..3 %, E_d 1 +-
  // 0.05..0.2 %, 1-10 mm scatter, 3-8 runs per direction, side 1-5 m)
  // calibrates (exit 0); the same campaign with one random mix-up never
  // does, and the message names the cause.
  std::mt19937_64 rng(424242);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto sign = [&] { return u(rng) < 0.5 ? -1.0 : 1.0; };
  const fs::path dir = umbmark::testing::TempDir("prop-mix");
  const char* const kMixups[] = {"errors in mm", "labels reversed", "side in mm", "wheelbase in mm", "diameters in mm"};
  const char* const kExpect[] = {"return errors are", "labels are reversed", "millimetres", "millimetres",
                                 "millimetres"};
  for (int trial = 0; trial < 30; ++trial) {
    const double E_b = 1.0 + sign() * (0.005 + 0.025 * u(rng)), E_d = 1.0 + sign() * (0.0005 + 0.0015 * u(rng));
    const double side = 1.0 + 4.0 * u(rng), sigma = 0.001 + 0.009 * u(rng), b = 0.2 + 0.4 * u(rng);
    const double D = 0.05 + 0.15 * u(rng);
    const int n = 3 + static_cast<int>(rng() % 6);
    const int mix = static_cast<int>(rng() % 5);
    std::normal_distribution<double> noise(0.0, sigma);
    std::string good = "run,direction,ex_m,ey_m\n", bad = good;
    int id = 0;
    for (const auto dir_ : {umbmark::SquareDirection::kCw, umbmark::SquareDirection::kCcw}) {
      const umbmark::Pose2 e = umbmark::SquareReturnError(dir_, side, b, E_b, umbmark::CorrectionLeft(E_d),
                                                         umbmark::CorrectionRight(E_d));
      const bool cw = dir_ == umbmark::SquareDirection::kCw;
      for (int i = 0; i < n; ++i) {
        const double x = e.x + noise(rng), y = e.y + noise(rng);
        good += fmt::format("{},{},{},{}\n", ++id, cw ? "cw" : "ccw", x, y);
        const double k = mix == 0 ? 1000.0 : 1.0;
        bad += fmt::format("{},{},{},{}\n", id, (mix == 1) != cw ? "cw" : "ccw", k * x, k * y);
      }
    }
    const auto robot = [&](double kb, double kd) {
      return fmt::format("wheelbase_m = {}\nwheel_diameter_left_m = {}\nwheel_diameter_right_m = {}\n", kb * b, kd * D,
                         kd * D);
    };
    Put(dir / "good.csv", good);
    Put(dir / "bad.csv", bad);
    Put(dir / "good.toml", robot(1.0, 1.0));
    Put(dir / "bad.toml", robot(mix == 3 ? 1000.0 : 1.0, mix == 4 ? 1000.0 : 1.0));
    const std::string tail = " --json -";
    const auto ok = RunCli("calibrate " + Q(dir / "good.csv") + " --robot " + Q(dir / "good.toml") +
                           fmt::format(" --side {}", side) + tail);
    const auto r = RunCli("calibrate " + Q(dir / "bad.csv") + " --robot " + Q(dir / "bad.toml") +
                          fmt::format(" --side {}", mix == 2 ? 1000.0 * side : side) + tail);
    INFO("trial " << trial << ": " << kMixups[mix] << ", E_b " << E_b << ", E_d " << E_d << ", side " << side
                  << ", sigma " << sigma << ", n " << n << "\n" << ok.err << "\n" << r.err);
    CHECK(ok.status == 0);
    if (ok.status == 0) CheckFinite(nlohmann::json::parse(ok.out), "calibrate");
    CHECK(r.status != 0);
    CHECK_THAT(r.err, Catch::Contains(kExpect[mix]));
  }
}
