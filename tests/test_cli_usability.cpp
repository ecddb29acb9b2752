// What a new user meets first: a missing file is bad input (exit 1),
// `CW` reads as `cw`, `umbmark help [COMMAND]`, `predict --robot` on a
// manifest, Monte Carlo standard errors, a campaign's square experiments
// pooled into one calibration, batch outputs named after the dataset, and
// every command saying what it wrote.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "support/run_cli.hpp"

using namespace umbmark::testing;
namespace fs = std::filesystem;

namespace {
const fs::path kSrc = UMBMARK_SOURCE_DIR;
const fs::path kEx = kSrc / "data/examples";

void Write(const fs::path& p, const std::string& text) {
  std::ofstream f(p, std::ios::binary);
  f << text;
}

/// Splits the example square campaign into two files by run id.
fs::path SplitCampaign(const fs::path& dir) {
  std::istringstream in(Slurp((kEx / "square_ticks.csv").string()));
  std::string line, a, b;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (line.rfind("run,", 0) == 0) {
      a += line + "\n";
      b += line + "\n";
      continue;
    }
    const std::string run = line.substr(0, line.find(','));
    (run == "4" || run == "5" || run == "9" || run == "10" ? b : a) += line + "\n";
  }
  Write(dir / "part_a.csv", a);
  Write(dir / "part_b.csv", b);
  const std::string robot = Slurp((kEx / "calibrate.toml").string());
  const std::string head = robot.substr(robot.find("[robot]"), robot.find("[[experiment]]") - robot.find("[robot]"));
  Write(dir / "campaign.toml", head +
                                   "[[experiment]]\nkind = \"square\"\nside_m = 1.0\nfile = \"part_a.csv\"\n\n"
                                   "[[experiment]]\nkind = \"back_and_forth\"\ndistance_m = 2.0\nfile = \"fb.csv\"\n\n"
                                   "[[experiment]]\nkind = \"square\"\nside_m = 1.0\nfile = \"part_b.csv\"\n");
  fs::copy_file(kEx / "fwd_back_travel.csv", dir / "fb.csv");
  return dir / "campaign.toml";
}
}  // namespace

TEST_CASE("a missing input file is bad input: exit 1 naming the file", "[cli][usability]") {
  const auto r = RunCli("calibrate /nonexistent/runs.csv --robot " + Q(kEx / "robot.toml") + " --side 1");
  CHECK(r.status == 1);
  CHECK(r.err.find("/nonexistent/runs.csv") != std::string::npos);
  const auto robot = RunCli("calibrate " + Q(kEx / "endpoints.csv") + " --robot /nonexistent/robot.toml --side 4");
  CHECK(robot.status == 1);
  CHECK(robot.err.find("/nonexistent/robot.toml") != std::string::npos);
  CHECK(RunCli("diagnose /nonexistent/campaign.toml").status == 1);
  CHECK(RunCli("fit-noise /nonexistent/x.csv --robot " + Q(kEx / "robot.toml")).status == 1);
  CHECK(RunCli("evaluate /nonexistent/x.csv --robot " + Q(kEx / "robot.toml")).status == 1);
}

TEST_CASE("square directions are case-insensitive", "[cli][usability]") {
  const fs::path dir = TempDir("upper");
  std::string text = Slurp((kEx / "endpoints.csv").string());
  for (std::string::size_type at = 0; (at = text.find(",cw,", at)) != std::string::npos;) text.replace(at, 4, ",CW,");
  for (std::string::size_type at = 0; (at = text.find(",ccw,", at)) != std::string::npos;) text.replace(at, 5, ",Ccw,");
  Write(dir / "upper.csv", text);
  const auto lower = RunCli("calibrate " + Q(kEx / "endpoints.csv") + " --robot " + Q(kEx / "robot.toml") + " --side 4 --json -");
  const auto upper = RunCli("calibrate " + Q(dir / "upper.csv") + " --robot " + Q(kEx / "robot.toml") + " --side 4 --json -");
  REQUIRE(lower.status == 0);
  REQUIRE(upper.status == 0);
  CHECK(nlohmann::json::parse(upper.out)["E_d"] == nlohmann::json::parse(lower.out)["E_d"]);
  CHECK(nlohmann::json::parse(upper.out)["runs"][0]["direction"] == "cw");
}

TEST_CASE("umbmark help [COMMAND]", "[cli][usability]") {
  const auto all = RunCli("help");
  CHECK(all.status == 0);
  CHECK(all.out.find("calibrate") != std::string::npos);
  CHECK(all.out.find("fit-noise") != std::string::npos);
  const auto one = RunCli("help calibrate");
  CHECK(one.status == 0);
  CHECK(one.out.find("--estimator") != std::string::npos);
  const auto nested = RunCli("help import optiodom");
  CHECK(nested.status == 0);
  CHECK(nested.out.find("--out") != std::string::npos);
  CHECK(RunCli("help frobnicate").status == 2);
}

TEST_CASE("predict takes a manifest's robot; Monte Carlo results carry standard errors", "[cli][usability]") {
  const auto r = RunCli("predict --robot " + Q(kEx / "calibrate.toml") +
                        " --kl 0.002 --kr 0.003 --path line:2,turn:1.5708,line:2 --monte-carlo 20000 --partitions 50"
                        " --seed 5 --threads 2 --json -");
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["wheelbase_m"].get<double>() == 0.2);
  const auto& mc = j.at("monte_carlo");
  // The mean's standard error is sqrt(var / n) exactly.
  for (int i = 0; i < 3; ++i)
    CHECK(mc["mean_se"][i].get<double>() ==
          Approx(std::sqrt(mc["covariance"][i][i].get<double>() / 20000.0)).epsilon(1e-12));
  // The Monte Carlo estimate lies within 4.5 standard errors of the second-order
  // closed form (which it estimates; 12 comparisons at ~1e-5 each).
  const auto& ref = j.at("second_order");
  for (int i = 0; i < 3; ++i) {
    INFO("mean " << i);
    CHECK(std::abs(mc["mean"][i].get<double>() - ref["mean"][i].get<double>()) < 4.5 * mc["mean_se"][i].get<double>());
    for (int k = i; k < 3; ++k) {
      INFO("covariance " << i << k);
      const double se = mc["covariance_se"][i][k].get<double>();
      CHECK(se > 0.0);
      CHECK(std::abs(mc["covariance"][i][k].get<double>() - ref["covariance"][i][k].get<double>()) < 4.5 * se);
    }
  }
}

TEST_CASE("a manifest's square experiments pool into one calibration", "[cli][usability]") {
  const fs::path dir = TempDir("pool");
  const fs::path manifest = SplitCampaign(dir);
  const auto whole = RunCli("calibrate " + Q(kEx / "calibrate.toml") + " --json -");
  const auto pooled = RunCli("calibrate " + Q(manifest) + " --json -");
  REQUIRE(whole.status == 0);
  INFO(pooled.err);
  REQUIRE(pooled.status == 0);
  const auto w = nlohmann::json::parse(whole.out), p = nlohmann::json::parse(pooled.out);
  // Same ten runs, split over two files: the same calibration.
  CHECK(p["E_d"].get<double>() == Approx(w["E_d"].get<double>()).epsilon(1e-12));
  CHECK(p["E_b"].get<double>() == Approx(w["E_b"].get<double>()).epsilon(1e-12));
  CHECK(p["runs"].size() == 10);
  CHECK(p["experiments"].size() == 2);
  CHECK(p["runs"][0]["run"] == "1:1");  // experiment 1, run 1
  // evaluate --params takes the pooled result.
  fs::path cal = dir / "cal.json";
  Write(cal, pooled.out);
  CHECK(RunCli("evaluate " + Q(manifest) + " --params " + Q(cal)).status == 0);
  // --per-experiment: one calibration each, outputs named after the dataset.
  const auto each = RunCli("calibrate " + Q(manifest) + " --per-experiment --ros2 " + Q(dir / "dd.yaml") + " --json " +
                           Q(dir / "each.json"));
  REQUIRE(each.status == 0);
  CHECK(nlohmann::json::parse(Slurp((dir / "each.json").string()))["results"].size() == 2);
  const std::string name = dir.filename().string();  // campaign.toml -> its folder
  CHECK(fs::exists(dir / ("dd-" + name + "-exp1.yaml")));
  CHECK(fs::exists(dir / ("dd-" + name + "-exp3.yaml")));
  // ... and says what it wrote.
  CHECK(each.out.find("wrote " + (dir / ("dd-" + name + "-exp3.yaml")).string()) != std::string::npos);
  CHECK(each.out.find("wrote " + (dir / "each.json").string()) != std::string::npos);
}

TEST_CASE("different square sides do not pool", "[cli][usability]") {
  const fs::path dir = TempDir("sides");
  const fs::path manifest = SplitCampaign(dir);
  std::string text = Slurp(manifest.string());
  text.replace(text.rfind("side_m = 1.0"), 12, "side_m = 2.0");
  Write(manifest, text);
  const auto r = RunCli("calibrate " + Q(manifest));
  CHECK(r.status == 1);
  CHECK(r.err.find("--per-experiment") != std::string::npos);
  CHECK(RunCli("calibrate " + Q(manifest) + " --per-experiment").status == 0);
}
