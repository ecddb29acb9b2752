// Campaign designs the data cannot support, end to end on simulated
// campaigns (whose truth is known): diagnose refuses back-and-forth-only
// campaigns (E_b undetermined) instead of fitting nonsense; calibrate
// --refine on trajectories with ground truth at the first and last sample
// only (the contract's minimum) fits the return errors and its 95 % interval
// covers the true E_b = 1 (with and without --fix scale); swapped encoder
// channels are named as such (exit 3).
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diagnosis/design_check.hpp"
#include "support/run_cli.hpp"

namespace fs = std::filesystem;
using umbmark::testing::Q;
using umbmark::testing::RunCli;
using umbmark::testing::Slurp;

namespace {

const char* kRobot =
    "[robot]\nwheelbase_m = 0.2\nwheel_diameter_left_m = 0.084\nwheel_diameter_right_m = 0.084\n"
    "ticks_per_rev = 2796.8\n\n";

void Put(const fs::path& p, const std::string& s) { std::ofstream(p, std::ios::binary) << s; }

/// Rewrites a trajectory CSV: `keep_gt(i, n)` says whether sample i of n in
/// a run keeps its ground truth; `swap` exchanges ticks_left and ticks_right.
std::string Rewrite(const std::string& csv, bool interior_gt, bool swap) {
  std::istringstream in(csv);
  std::string line, out;
  std::vector<std::vector<std::string>> run;
  std::string current;
  auto flush = [&] {
    for (std::size_t i = 0; i < run.size(); ++i) {
      auto c = run[i];
      if (!interior_gt && i > 0 && i + 1 < run.size()) c[5] = c[6] = c[7] = "";
      if (swap) std::swap(c[3], c[4]);
      for (std::size_t k = 0; k < c.size(); ++k) out += (k ? "," : "") + c[k];
      out += "\n";
    }
    run.clear();
  };
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("run,", 0) == 0) {
      out += line + "\n";
      continue;
    }
    std::vector<std::string> c;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) c.push_back(cell);
    c.resize(8);
    if (c[0] != current) flush();
    current = c[0];
    run.push_back(c);
  }
  flush();
  return out;
}

}  // namespace

TEST_CASE("design check: back-and-forth alone cannot determine E_b", "[safety][diagnose]") {
  umbmark::Manifest m;
  umbmark::Experiment bf;
  bf.kind = umbmark::ExperimentKind::kBackAndForth;
  bf.distance_m = 3.0;
  m.experiments = {bf, bf};
  CHECK_THAT(umbmark::diag::CampaignDesignProblem(m), Catch::Contains("E_b cannot be determined"));
  umbmark::Experiment sq;
  sq.kind = umbmark::ExperimentKind::kSquare;
  sq.side_m = 2.0;
  m.experiments.push_back(sq);
  CHECK(umbmark::diag::CampaignDesignProblem(m).empty());

  const fs::path dir = umbmark::testing::TempDir("design");
  Put(dir / "m.toml", std::string(kRobot) + "[[experiment]]\nkind = \"back_and_forth\"\ndistance_m = 3.0\nfile = \"bf.csv\"\n");
  REQUIRE(RunCli("simulate " + Q(dir / "m.toml") + " --out " + Q(dir / "c") + " --back-and-forth-runs 4").status == 0);
  const auto r = RunCli("diagnose " + Q(dir / "c/campaign.toml") + " --null-sims 20");
  CHECK(r.status == 1);
  CHECK_THAT(r.err, Catch::Contains("add a square experiment"));
  CHECK(r.out.empty());
}

TEST_CASE("refine with ground truth at the ends only fits the return errors and covers the truth",
          "[safety][refine]") {
  const fs::path dir = umbmark::testing::TempDir("sparse");
  Put(dir / "m.toml", std::string(kRobot) + "[[experiment]]\nkind = \"square\"\nside_m = 2.0\nfile = \"sq.csv\"\n");
  REQUIRE(RunCli("simulate " + Q(dir / "m.toml") + " --out " + Q(dir / "c") + " --square-runs 5 --seed 11").status == 0);
  Put(dir / "robot.toml", std::string(kRobot).substr(8));
  Put(dir / "sparse.csv", Rewrite(Slurp((dir / "c/sq.csv").string()), false, false));
  for (const char* extra : {"", " --fix scale"}) {
    INFO("extra:" << extra);
    const auto r = RunCli("calibrate " + Q(dir / "sparse.csv") + " --robot " + Q(dir / "robot.toml") +
                          " --side 2 --refine --json -" + extra);
    INFO(r.err);
    REQUIRE(r.status == 0);
    const auto j = nlohmann::json::parse(r.out);
    CHECK(j["refined"]["input"] == "return_errors");
    const auto& eb = j["refined"]["intervals"]["E_b"];
    CHECK(eb["low"].get<double>() <= 1.0);
    CHECK(eb["high"].get<double>() >= 1.0);
    CHECK_THAT(j["warnings"].dump(), Catch::Contains("ground truth only at the first and last sample"));
  }
}

TEST_CASE("swapped encoder channels are named", "[safety][calibrate]") {
  const fs::path dir = umbmark::testing::TempDir("swapped");
  Put(dir / "m.toml", std::string(kRobot) + "[[experiment]]\nkind = \"square\"\nside_m = 2.0\nfile = \"sq.csv\"\n");
  REQUIRE(RunCli("simulate " + Q(dir / "m.toml") + " --out " + Q(dir / "c") + " --square-runs 3").status == 0);
  Put(dir / "robot.toml", std::string(kRobot).substr(8));
  Put(dir / "swapped.csv", Rewrite(Slurp((dir / "c/sq.csv").string()), true, true));
  const auto r = RunCli("calibrate " + Q(dir / "swapped.csv") + " --robot " + Q(dir / "robot.toml") + " --side 2");
  CHECK(r.status == 3);
  CHECK_THAT(r.err, Catch::Contains("encoder channels"));
  CHECK(r.out.empty());
}
