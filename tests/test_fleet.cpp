// Fleet summary (`umbmark summarize`): a generated fleet of 40 robots around
// nominal parameters with two planted outliers (a worn left wheel, a
// mis-assembled wheelbase) plus one real calibrate output: exactly the planted
// robots are flagged, with the right reasons; the fleet median and MAD equal
// an independent computation.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "calibration/fleet.hpp"
#include "support/run_cli.hpp"

using namespace umbmark;
using namespace umbmark::testing;
namespace fs = std::filesystem;

namespace {
const fs::path kEx = fs::path(UMBMARK_SOURCE_DIR) / "data/examples";

double SortedMedian(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// 40 robots: wheelbase 0.2 m, diameters 0.084 m, each with 0.05% production
// spread; robot 7 has a left wheel worn by 1.5%, robot 23 a wheelbase 3% long.
std::vector<nlohmann::json> Fleet() {
  std::mt19937_64 rng(2024);
  std::normal_distribution<double> n(0.0, 5e-4);
  std::vector<nlohmann::json> out;
  for (int i = 0; i < 40; ++i) {
    double b = 0.2 * (1 + n(rng)), dl = 0.084 * (1 + n(rng)), dr = 0.084 * (1 + n(rng));
    if (i == 7) dl *= 0.985;
    if (i == 23) b *= 1.03;
    const double ed = dr / dl, eb = b / 0.2;
    out.push_back({{"E_d", ed},
                   {"E_b", eb},
                   {"E_max_syst_m", 0.01 * (1 + n(rng))},
                   {"parameters", {{"wheelbase_m", b}, {"wheel_diameter_left_m", dl}, {"wheel_diameter_right_m", dr}}}});
  }
  return out;
}
}  // namespace

TEST_CASE("SummarizeFleet flags the planted outliers and only them", "[fleet]") {
  std::vector<FleetRobot> robots;
  for (const auto& j : Fleet()) {
    FleetRobot r;
    r.values[FleetQuantity::kWheelbase] = j["parameters"]["wheelbase_m"];
    r.values[FleetQuantity::kDiameterLeft] = j["parameters"]["wheel_diameter_left_m"];
    r.values[FleetQuantity::kDiameterRight] = j["parameters"]["wheel_diameter_right_m"];
    r.values[FleetQuantity::kEd] = j["E_d"];
    robots.push_back(r);
  }
  const FleetSummary s = SummarizeFleet(robots);
  for (std::size_t i = 0; i < robots.size(); ++i) {
    INFO("robot " << i);
    CHECK(s.robots[i].outlier == (i == 7 || i == 23));
  }
  // Worn left wheel: the diameter and the ratio stand out; the first reason names the wheel.
  CHECK(s.robots[7].z.at(FleetQuantity::kDiameterLeft) < -3.5);
  CHECK(s.robots[7].z.at(FleetQuantity::kEd) > 3.5);
  CHECK(s.robots[7].reasons.front().find("left wheel diameter") != std::string::npos);
  CHECK(s.robots[7].reasons.front().find("worn") != std::string::npos);
  CHECK(s.robots[23].reasons.front().find("mis-assembled") != std::string::npos);
  // Median and MAD against a sort-based computation.
  std::vector<double> wb;
  for (const auto& r : robots) wb.push_back(r.values.at(FleetQuantity::kWheelbase));
  const double med = SortedMedian(wb);
  std::vector<double> dev;
  for (double v : wb) dev.push_back(std::abs(v - med));
  CHECK(s.fleet.at(FleetQuantity::kWheelbase).median == med);
  CHECK(s.fleet.at(FleetQuantity::kWheelbase).mad == Approx(1.4826 * SortedMedian(dev)).epsilon(1e-12));
  // 1.4826 MAD estimates the production spread (0.05% of 0.2 m = 1e-4 m) within sampling error.
  CHECK(s.fleet.at(FleetQuantity::kWheelbase).mad == Approx(1e-4).epsilon(0.35));
}

TEST_CASE("umbmark summarize: JSON keys, CSV, report, and a real calibrate output among generated ones", "[fleet][cli]") {
  const fs::path dir = TempDir("fleet");
  std::vector<std::string> files;
  int k = 0;
  for (const auto& j : Fleet()) {
    const fs::path f = dir / ("robot" + std::to_string(k++) + ".json");
    std::ofstream(f) << j.dump();
    files.push_back(f.string());
  }
  const fs::path real = dir / "real.json";
  REQUIRE(RunCli("calibrate " + Q(kEx / "endpoints.csv") + " --robot " + Q(kEx / "robot.toml") + " --side 4 --json " + Q(real)).status == 0);
  std::string args = "summarize";
  for (const auto& f : files) args += " " + Q(f);
  args += " " + Q(real) + " --json - --csv " + Q(dir / "fleet.csv") + " --report " + Q(dir / "fleet.html");
  const auto r = RunCli(args);
  INFO(r.err);
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.out);
  REQUIRE(j.at("robots").size() == 41);
  for (const char* key : {"file", "parameters", "outlier", "outlier_reasons"}) CHECK(j["robots"][0].contains(key));
  CHECK(j["robots"][7]["outlier"] == true);
  CHECK(j["robots"][23]["outlier"] == true);
  CHECK(j["robots"][3]["outlier"] == false);
  CHECK(j["robots"][40]["file"] == real.string());
  for (const char* q : {"wheelbase_m", "wheel_diameter_left_m", "wheel_diameter_right_m"}) {
    CHECK(j["fleet"][q]["median"].is_number());
    CHECK(j["fleet"][q]["mad"].is_number());
  }
  CHECK(j.at("warnings").is_array());
  const std::string csv = Slurp((dir / "fleet.csv").string());
  CHECK(std::count(csv.begin(), csv.end(), '\n') == 42);
  const std::string html = Slurp((dir / "fleet.html").string());
  CHECK(html.find(std::to_string(j["outliers"].get<int>()) + " of 41 robots stand out") != std::string::npos);
  // Not JSON: exit 1 naming the file.
  std::ofstream(dir / "bad.json") << "{ not json";
  const auto bad = RunCli("summarize " + Q(dir / "bad.json"));
  CHECK(bad.status == 1);
  CHECK(bad.err.find("bad.json") != std::string::npos);
}
