// ROS 2 parameter files: `calibrate --ros2` and `fit-noise --ros2` write YAML
// that a YAML parser (yaml-cpp) reads as the diff_drive_controller
// parameters, every value a float; the covariance diagonals follow the
// wheel noise model, checked against Monte Carlo simulations (our own
// wheel-noise draw here, and `predict --monte-carlo`).
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <random>

#include "core/errors.hpp"
#include "error_models/odometry_covariance.hpp"
#include "formats/ros2_params.hpp"
#include "support/run_cli.hpp"

using namespace umbmark;
using umbmark::testing::Q;
using umbmark::testing::RunCli;
using umbmark::testing::TempDir;
namespace fs = std::filesystem;

namespace {

const fs::path kBags = fs::path(UMBMARK_SOURCE_DIR) / "tests/data/rosbag2";

// A parameter as ROS 2 types it: a double needs a '.', an exponent or nan/inf.
bool LooksDouble(const YAML::Node& n) { return n.Scalar().find_first_of(".eEn") != std::string::npos; }

fs::path ImportedBags() {
  static const fs::path dir = [] {
    const fs::path d = TempDir("ros2-params");
    std::string args = "import rosbag2";
    for (int k = 1; k <= 6; ++k) args += " " + Q(kBags / ("square_run" + std::to_string(k) + ".mcap"));
    const auto r = RunCli(args + " --out " + Q(d) + " --experiment square --side 0.75 --robot " + Q(kBags / "robot.toml") +
                          " --wheels /joint_states --ground-truth /mocap/pose --pause 0");
    REQUIRE(r.status == 0);
    return d;
  }();
  return dir;
}

}  // namespace

TEST_CASE("diff_drive_controller calibration YAML: controller, multipliers as floats, robot in comments", "[ros2]") {
  RobotParams robot;
  robot.wheelbase_m = 0.34;
  robot.wheel_diameter_left_m = 0.1524;
  robot.wheel_diameter_right_m = 0.15;
  const std::string text = io::FormatDiffDriveCalibration("base/diff_cont", {1.0, 1.0003, 0.9997}, robot, {"test"});
  const YAML::Node doc = YAML::Load(text);
  const YAML::Node p = doc["base/diff_cont"]["ros__parameters"];
  REQUIRE(p.IsMap());
  CHECK(p.size() == 3);
  CHECK(p["wheel_separation_multiplier"].as<double>() == 1.0);
  CHECK(LooksDouble(p["wheel_separation_multiplier"]));  // "1.0", not "1"
  CHECK(p["left_wheel_radius_multiplier"].as<double>() == 1.0003);
  CHECK(p["right_wheel_radius_multiplier"].as<double>() == 0.9997);
  CHECK_THAT(text, Catch::Contains("wheel_separation: 0.34") && Catch::Contains("wheel_radius: 0.0762 (left), 0.075 (right)"));
  CHECK_THROWS_AS(io::FormatDiffDriveCalibration("bad name", {}, robot, {}), InvalidOptions);
}

TEST_CASE("calibrate --ros2 on the converted bags: the multipliers of the JSON result", "[ros2][cli]") {
  const fs::path dir = TempDir("ros2-cal");
  const auto r = RunCli("calibrate " + Q(ImportedBags() / "campaign.toml") +
                        " --estimator x --integrator midpoint --use classic --json - --ros2 " + Q(dir / "ddc.yaml") +
                        " --controller my_ddc");
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.out);
  const YAML::Node p = YAML::LoadFile((dir / "ddc.yaml").string())["my_ddc"]["ros__parameters"];
  REQUIRE(p.IsMap());
  CHECK_THAT(p["wheel_separation_multiplier"].as<double>(), Catch::WithinRel(j["parameters"]["wheelbase_m"].get<double>() / 0.2, 1e-12));
  CHECK_THAT(p["left_wheel_radius_multiplier"].as<double>(),
             Catch::WithinRel(j["parameters"]["wheel_diameter_left_m"].get<double>() / 0.084, 1e-12));
  CHECK_THAT(p["right_wheel_radius_multiplier"].as<double>(),
             Catch::WithinRel(j["parameters"]["wheel_diameter_right_m"].get<double>() / 0.084, 1e-12));
  // The published calibration of this dataset: wheelbase 0.201458 m.
  CHECK_THAT(p["wheel_separation_multiplier"].as<double>() * 0.2, Catch::WithinAbs(0.201458, 1e-6));
}

TEST_CASE("Odometry covariance from wheel noise: closed form vs Monte Carlo", "[ros2][covariance]") {
  const double kl = 0.004, kr = 0.006, b = 0.34;
  OdometryCovarianceOptions o;
  o.rate_hz = 20.0;
  o.speed_mps = 0.8;
  const auto c = OdometryCovarianceFromWheelNoise(kl, kr, b, o);
  const double ds = o.speed_mps / o.rate_hz;

  // Wheel errors per update drawn from the model: N(0, k^2 ds) per wheel.
  std::mt19937_64 rng(20240611);
  std::normal_distribution<double> el(0.0, kl * std::sqrt(ds)), er(0.0, kr * std::sqrt(ds));
  const int n = 400000;
  double sv = 0, sv2 = 0, sw = 0, sw2 = 0;
  for (int i = 0; i < n; ++i) {
    const double dl = ds + el(rng), dr = ds + er(rng);
    const double v = 0.5 * (dl + dr) * o.rate_hz, w = (dr - dl) / b * o.rate_hz;
    sv += v;
    sv2 += v * v;
    sw += w;
    sw2 += w * w;
  }
  const double var_v = (sv2 - sv * sv / n) / (n - 1), var_w = (sw2 - sw * sw / n) / (n - 1);
  // Relative standard error of a sample variance: sqrt(2/n) = 0.22%; 1.5% is ~7 sigma.
  CHECK_THAT(var_v, Catch::WithinRel(c.twist[0], 0.015));
  CHECK_THAT(var_w, Catch::WithinRel(c.twist[5], 0.015));

  // The pose increment of one update against the suite's own Monte Carlo
  // predictor (predict --monte-carlo on a straight segment of ds).
  const fs::path dir = TempDir("ros2-cov");
  {
    std::ofstream f(dir / "robot.toml");
    f << "wheelbase_m = 0.34\nwheel_diameter_left_m = 0.15\nwheel_diameter_right_m = 0.15\n";
  }
  const auto r = RunCli(fmt::format("predict --robot {} --kl {} --kr {} --path line:{} --monte-carlo 200000 --partitions 8 "
                                    "--seed 7 --threads 1 --json -",
                                    Q(dir / "robot.toml"), kl, kr, ds));
  REQUIRE(r.status == 0);
  const auto mc = nlohmann::json::parse(r.out)["monte_carlo"]["covariance"];
  CHECK_THAT(mc[0][0].get<double>(), Catch::WithinRel(c.pose[0], 0.03));
  CHECK_THAT(mc[2][2].get<double>(), Catch::WithinRel(c.pose[5], 0.03));
  CHECK_THAT(mc[1][1].get<double>(), Catch::WithinRel(c.pose[1], 0.05));
  CHECK(c.pose[2] == kUnmeasuredVariance);
  CHECK(c.twist[1] == kConstraintVariance);
  CHECK_THROWS_AS(OdometryCovarianceFromWheelNoise(kl, kr, b, {0.0, 1.0}), InvalidOptions);
}

TEST_CASE("fit-noise --ros2: the covariance diagonals of the fitted k_L, k_R as ROS 2 floats", "[ros2][cli]") {
  const fs::path dir = TempDir("ros2-noise");
  // Six squares with E_d estimated from the same runs leave one degree of
  // freedom: k's 95 % upper bound (0.29 m^1/2) says nothing, so no
  // covariance is written (exit 3, the hint names what would determine k).
  const auto refused = RunCli("fit-noise " + Q(ImportedBags() / "campaign.toml") + " --ros2 " + Q(dir / "cov.yaml"));
  CHECK(refused.status == 3);
  CHECK(refused.err.find("is not determined by these 6 runs") != std::string::npos);
  CHECK(refused.err.find("--params CAL.json") != std::string::npos);
  CHECK(refused.err.find("--meas-sigma") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "cov.yaml"));
  // With the calibration the fit keeps two degrees of freedom: k_L sits at
  // 0 with an upper bound of 1.5e-3, and the covariance uses that bound.
  const auto cal = RunCli("calibrate " + Q(ImportedBags() / "campaign.toml") + " --json " + Q(dir / "cal.json"));
  REQUIRE(cal.status == 0);
  const auto r = RunCli("fit-noise " + Q(ImportedBags() / "campaign.toml") + " --params " + Q(dir / "cal.json") +
                        " --json - --ros2 " + Q(dir / "cov.yaml") + " --rate 25 --speed 0.3");
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.out);
  REQUIRE_FALSE(j["k_L_determined"].get<bool>());
  CHECK(j["ros2"]["k_L_source"] == "upper95");
  CHECK(j["ros2"]["k_L"].get<double>() == j["k_L_upper95"].get<double>());
  CHECK(j["ros2"]["k_L"].get<double>() > 100 * j["k_L"].get<double>());
  CHECK(j["ros2"]["k_R"].get<double>() == j["k_R"].get<double>());
  bool warned = false;
  for (const auto& w : j["warnings"]) warned |= w.get<std::string>().find("95 % upper bound") != std::string::npos;
  CHECK(warned);
  const std::string yaml = umbmark::testing::Slurp((dir / "cov.yaml").string());
  CHECK(yaml.find("# k_L is not determined by the runs") != std::string::npos);
  const double kl = j["ros2"]["k_L"], kr = j["ros2"]["k_R"];
  const YAML::Node p = YAML::LoadFile((dir / "cov.yaml").string())["diff_drive_controller"]["ros__parameters"];
  REQUIRE(p["pose_covariance_diagonal"].size() == 6);
  REQUIRE(p["twist_covariance_diagonal"].size() == 6);
  for (int i = 0; i < 6; ++i) {
    CHECK(LooksDouble(p["pose_covariance_diagonal"][i]));
    CHECK(LooksDouble(p["twist_covariance_diagonal"][i]));
  }
  const double k2 = kl * kl + kr * kr;
  CHECK_THAT(p["twist_covariance_diagonal"][0].as<double>(), Catch::WithinRel(k2 * 0.3 * 25 / 4, 1e-12));
  CHECK_THAT(p["twist_covariance_diagonal"][5].as<double>(), Catch::WithinRel(k2 * 0.3 * 25 / (0.2 * 0.2), 1e-12));
  CHECK_THAT(p["pose_covariance_diagonal"][0].as<double>(), Catch::WithinRel(k2 * (0.3 / 25) / 4, 1e-12));
  CHECK_THAT(j["ros2"]["twist_covariance_diagonal"][5].get<double>(), Catch::WithinRel(k2 * 0.3 * 25 / 0.04, 1e-12));
}
