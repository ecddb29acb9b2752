// `umbmark predict` end to end: the contract's JSON keys, line:10,line:-10
// with Chong & Kleeman's constants against many-segment numerical
// propagation (1e-9 relative), the Monte Carlo block, and exit codes.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "support/run_cli.hpp"

#include "error_models/numerical_propagation.hpp"

using namespace umbmark;
namespace fs = std::filesystem;

namespace {

testing::CliResult Run(const std::string& args) { return testing::RunCli(args); }

fs::path RobotFile() {
  const fs::path p = fs::temp_directory_path() / fmt::format("umbmark_predict_robot_{}.toml", ::getpid());
  std::ofstream(p) << "wheelbase_m = 0.371\nwheel_diameter_left_m = 0.1\nwheel_diameter_right_m = 0.1\n";
  return p;
}

}  // namespace

TEST_CASE("predict line:10,line:-10 matches numerical propagation to 1e-9", "[predict_cli]") {
  const fs::path robot = RobotFile();
  const auto r = Run(fmt::format("predict --robot {} --kl 0.00040 --kr 0.00058 --path line:10,line:-10 --json -",
                                   robot.string()));
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.out);
  REQUIRE(j["mean"].size() == 3);
  REQUIRE(j["covariance"].size() == 3);
  const std::vector<WheelSegment> path{{10.0, 10.0}, {-10.0, -10.0}};
  const PoseCovariance ref = NumericalPathCovarianceBasis(path, 0.371).Evaluate(WheelNoise{0.00040, 0.00058});
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      CHECK(std::abs(j["covariance"][a][b].get<double>() - ref(a, b)) <= 1e-9 * std::sqrt(ref(a, a) * ref(b, b)));
  CHECK(std::abs(j["mean"][0].get<double>()) < 1e-12);
  // The second-order block adds the track shortening to ex only.
  CHECK(j["second_order"]["covariance"][0][0].get<double>() > 1.03 * ref(0, 0));
  CHECK(j["second_order"]["covariance"][1][1].get<double>() == Approx(ref(1, 1)).epsilon(1e-9));
  CHECK(j["second_order"]["mean"][0].get<double>() == Approx(1.80e-4).epsilon(0.01));
  fs::remove(robot);
}

TEST_CASE("predict --monte-carlo reports the contract's block", "[predict_cli]") {
  const fs::path robot = RobotFile();
  const auto r = Run(fmt::format(
      "predict --robot {} --kl 0.003 --kr 0.002 --path arc:3:1 --P0 0.0025,0.0025,0.0012 --monte-carlo 4000 "
      "--partitions 200 --seed 9 --threads 2 --json -",
      robot.string()));
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.out);
  const auto& mc = j["monte_carlo"];
  for (const char* key : {"mean", "covariance", "runs", "partitions", "seed", "threads", "steps_per_second"})
    CHECK(mc.contains(key));
  CHECK(mc["runs"] == 4000);
  CHECK(mc["partitions"] == 200);
  CHECK(mc["seed"] == 9);
  CHECK(mc["threads"] == 2);
  CHECK(mc["steps_per_second"].get<double>() > 0.0);
  // Mean and covariance agree with the closed form within sampling error (z <= 4).
  for (int a = 0; a < 3; ++a) {
    const double var = j["covariance"][a][a];
    CHECK(std::abs(mc["mean"][a].get<double>() - j["mean"][a].get<double>()) < 4.0 * std::sqrt(var / 4000));
    CHECK(std::abs(mc["covariance"][a][a].get<double>() - var) < 4.0 * var * std::sqrt(2.0 / 4000));
  }
  // Same seed, same numbers, any thread count.
  const auto r1 = Run(fmt::format(
      "predict --robot {} --kl 0.003 --kr 0.002 --path arc:3:1 --P0 0.0025,0.0025,0.0012 --monte-carlo 4000 "
      "--partitions 200 --seed 9 --threads 1 --json -",
      robot.string()));
  const auto j1 = nlohmann::json::parse(r1.out);
  CHECK(j1["monte_carlo"]["covariance"] == mc["covariance"]);
  fs::remove(robot);
}

TEST_CASE("predict exit codes", "[predict_cli]") {
  const fs::path robot = RobotFile();
  const std::string base = fmt::format("predict --robot {} --kl 0.001 --kr 0.001", robot.string());
  CHECK(Run(base + " --path line:1").status == 0);
  CHECK(Run(base + " --path spiral:1").status == 2);
  CHECK(Run(base + " --path line:1 --P0 1,2,3,4").status == 2);
  CHECK(Run(fmt::format("predict --robot {} --kl -1 --kr 0.001 --path line:1", robot.string())).status == 2);
  CHECK(Run("predict --kl 0.001 --kr 0.001 --path line:1").status == 2);  // no robot
  const fs::path bad = fs::temp_directory_path() / fmt::format("umbmark_predict_bad_{}.toml", ::getpid());
  std::ofstream(bad) << "wheelbase_m = \"wide\"\n";
  CHECK(Run(fmt::format("predict --robot {} --kl 0.001 --kr 0.001 --path line:1", bad.string())).status == 1);
  fs::remove(bad);
  fs::remove(robot);
}
