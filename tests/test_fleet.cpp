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

// Issue 23: E_d, E_b and E_max_syst_m are relative to the parameters the
// odometry used (recorded_parameters); a robot recorded with another robot
// file (0.205 m instead of 0.2 m) whose true wheelbase is the fleet's has
// E_b = 0.2 / 0.205 = 0.9756 and must not be called mis-assembled, while a
// robot recorded with 0.2 m whose wheelbase really is 3 % long still is.
TEST_CASE("summarize compares E_b and E_d only between robots with the same recorded parameters", "[fleet][cli]") {
  const fs::path dir = TempDir("fleet-recorded");
  std::mt19937_64 rng(77);
  std::normal_distribution<double> n(0.0, 5e-4);
  std::string args = "summarize";
  for (int i = 0; i < 12; ++i) {
    const double recorded_b = i == 4 ? 0.205 : 0.2;
    double b = 0.2 * (1 + n(rng));
    if (i == 9) b *= 1.03;
    const double dl = 0.084 * (1 + n(rng)), dr = 0.084 * (1 + n(rng));
    const nlohmann::json j = {
        {"E_d", dr / dl},
        {"E_b", b / recorded_b},
        {"E_max_syst_m", 0.01 * (1 + n(rng)) * (i == 4 ? 3.0 : 1.0)},
        {"parameters", {{"wheelbase_m", b}, {"wheel_diameter_left_m", dl}, {"wheel_diameter_right_m", dr}}},
        {"recorded_parameters",
         {{"wheelbase_m", recorded_b}, {"wheel_diameter_left_m", 0.084}, {"wheel_diameter_right_m", 0.084}}}};
    const fs::path f = dir / ("r" + std::to_string(i) + ".json");
    std::ofstream(f) << j.dump();
    args += " " + Q(f);
  }
  const auto r = RunCli(args + " --json -");
  INFO(r.err);
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.out);
  REQUIRE(j["robots"].size() == 12);
  // Robot 4 (another robot file, the fleet's true wheelbase): nothing about
  // its wheelbase, E_b or its error before calibration. (Its diameters are
  // random production spread like everyone's, scored as usual.)
  INFO("robot 4: " << j["robots"][4]["outlier_reasons"].dump());
  for (const auto& reason : j["robots"][4]["outlier_reasons"]) {
    const std::string text = reason.get<std::string>();
    CHECK(text.find("wheelbase") == std::string::npos);
    CHECK(text.find("E_b") == std::string::npos);
    CHECK(text.find("systematic error") == std::string::npos);
  }
  // Robot 9 (recorded 0.2 m, truly 3 % wide): mis-assembled, by its absolute wheelbase and by E_b.
  INFO("robot 9: " << j["robots"][9]["outlier_reasons"].dump());
  CHECK(j["robots"][9]["outlier"] == true);
  CHECK(j["robots"][9]["outlier_reasons"][0].get<std::string>().find("mis-assembled") != std::string::npos);
  // Robot 4 alone in its group: no relative z-score at all; its absolute wheelbase is scored.
  CHECK_FALSE(j["robots"][4]["robust_z"].contains("E_b"));
  CHECK(j["robots"][4]["robust_z"].contains("wheelbase_m"));
  CHECK(j["robots"][9]["robust_z"]["E_b"].get<double>() > 3.5);
  bool warned = false;
  for (const auto& w : j["warnings"]) warned = warned || w.get<std::string>().find("2 different parameter sets") != std::string::npos;
  CHECK(warned);

  // The library on its own: the same split by FleetRobot::recorded.
  std::vector<FleetRobot> robots(6);
  for (std::size_t i = 0; i < robots.size(); ++i) {
    robots[i].recorded = FleetRecordedKey(i < 3 ? 0.2 : 0.3, 0.084, 0.084);
    robots[i].values[FleetQuantity::kEb] = (i < 3 ? 1.0 : 1.1) + 1e-3 * static_cast<double>(i % 3);
    robots[i].values[FleetQuantity::kWheelbase] = 0.2 + 1e-4 * static_cast<double>(i);
  }
  const FleetSummary s = SummarizeFleet(robots);
  CHECK(s.groups == 2);
  for (std::size_t i = 0; i < robots.size(); ++i) {
    INFO("robot " << i);
    CHECK_FALSE(s.robots[i].outlier);  // 1.0 vs 1.1 is the robot files' difference, not the robots'
    CHECK(s.robots[i].reference.at(FleetQuantity::kEb).median == Approx(i < 3 ? 1.001 : 1.101));
  }
}

// Issue 31: robots are named by their robot id (robot file -> calibrate JSON
// -> summarize) or their file's stem, never by path; the report lists the
// outlier robots only, each by name.
TEST_CASE("summarize names robots by robot_id or file stem; the report's table holds the outliers only", "[fleet][cli]") {
  const fs::path dir = TempDir("fleet-names");
  // A robot file with an id: calibrate copies it into its JSON.
  std::ofstream(dir / "robot.toml") << Slurp((kEx / "robot.toml").string()) << "robot_id = \"SN-7731\"\n";
  const fs::path real = dir / "real.json";
  const auto cal = RunCli("calibrate " + Q(kEx / "endpoints.csv") + " --robot " + Q(dir / "robot.toml") +
                          " --side 4 --no-heldout --json " + Q(real));
  INFO(cal.err);
  REQUIRE(cal.status == 0);
  CHECK(nlohmann::json::parse(Slurp(real.string()))["robot_id"] == "SN-7731");
  // The generated fleet: ids on every fifth robot, file stems elsewhere, two files with one stem.
  std::string args = "summarize";
  int k = 0;
  for (auto j : Fleet()) {
    if (k % 5 == 0) j["robot_id"] = "R-" + std::to_string(k);
    const fs::path sub = dir / (k == 11 ? "b" : "a");
    fs::create_directories(sub);
    const fs::path f = sub / (k == 11 ? "robot10.json" : "robot" + std::to_string(k) + ".json");
    std::ofstream(f) << j.dump();
    args += " " + Q(f);
    ++k;
  }
  const auto r = RunCli(args + " " + Q(real) + " --json - --report " + Q(dir / "fleet.html"));
  INFO(r.err);
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["robots"][5]["robot"] == "R-5");
  CHECK(j["robots"][5]["robot_id"] == "R-5");
  CHECK(j["robots"][7]["robot"] == "robot7");
  CHECK(j["robots"][7]["robot_id"].is_null());
  CHECK(j["robots"][10]["robot"] == "R-10");  // a/robot10.json has the id R-10
  CHECK(j["robots"][11]["robot"] == "robot10");  // b/robot10.json: its stem, free
  CHECK(j["robots"][40]["robot"] == "SN-7731");
  CHECK(j["robots"][7]["file"] == (dir / "a" / "robot7.json").string());  // the path stays in `file`
  const std::string html = Slurp((dir / "fleet.html").string());
  const auto table = html.substr(html.find("Outlier robots"), html.find("Fleet distribution") - html.find("Outlier robots"));
  CHECK(table.find("<td>robot7</td>") != std::string::npos);    // worn left wheel
  CHECK(table.find("<td>robot23</td>") != std::string::npos);   // mis-assembled
  CHECK(table.find("<td>robot3</td>") == std::string::npos);    // within the fleet: not in the table
  CHECK(std::count(table.begin(), table.end(), '\n') == static_cast<long>(j["outliers"].get<int>()) + 3);  // heading, table head, rows, table end
  CHECK(html.find(dir.string()) == std::string::npos);          // no path anywhere on the page
  CHECK(html.find("data-title=\"Corrected wheelbase (41 robots)\"") != std::string::npos);

  // A robot id with a control character is refused at its value.
  std::ofstream(dir / "bad.toml") << "wheelbase_m = 0.2\nwheel_diameter_left_m = 0.084\nwheel_diameter_right_m = 0.084\n"
                                  << "robot_id = \"R\\u0007\"\n";
  const auto bad = RunCli("calibrate " + Q(kEx / "endpoints.csv") + " --robot " + Q(dir / "bad.toml") + " --side 4");
  CHECK(bad.status == 1);
  CHECK(bad.err.find("bad.toml:4:12: robot_id contains a control character") != std::string::npos);
}
