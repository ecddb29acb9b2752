// End-to-end tests of the `umbmark` executable: contract JSON keys, exit
// codes, the bad-input corpus through the CLI, batch runs, atomic outputs,
// and inputs left untouched.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "calibration/calibrate_job.hpp"
#include "import/optiodom.hpp"
#include "support/run_cli.hpp"

using namespace umbmark;
using namespace umbmark::testing;
namespace fs = std::filesystem;

namespace {
const fs::path kSrc = UMBMARK_SOURCE_DIR;
const fs::path kSquare = kSrc / "data/optiodom-2020-06/square/230620202042";
const fs::path kGood = kSrc / "tests/data/good";
const fs::path kBad = kSrc / "tests/data/bad";

fs::path Imported() {
  static fs::path dir;
  if (dir.empty()) {
    dir = TempDir("import");
    const auto r = RunCli("import optiodom " + Q(kSquare) + " --out " + Q(dir));
    REQUIRE(r.status == 0);
  }
  return dir;
}
}  // namespace

TEST_CASE("calibrate --json - writes the contract keys, and only JSON", "[cli]") {
  const auto r = RunCli("calibrate " + Q(Imported() / "campaign.toml") + " --estimator x --integrator midpoint --json -");
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.out);  // throws if anything but JSON is on stdout
  for (const char* key : {"E_d", "E_b", "alpha_rad", "beta_rad", "c_L", "c_R", "E_max_syst_m"}) {
    INFO(key);
    CHECK(j.at(key).is_number());
  }
  for (const char* key : {"wheelbase_m", "wheel_diameter_left_m", "wheel_diameter_right_m"})
    CHECK(j.at("parameters").at(key).is_number());
  // Published OptiOdom UMBmark result for this dataset (published-results.csv).
  CHECK(j["parameters"]["wheelbase_m"].get<double>() == Approx(0.201458).margin(1e-6));
  CHECK(j["parameters"]["wheel_diameter_right_m"].get<double>() == Approx(0.083954).margin(1e-6));
  CHECK(j["parameters"]["wheel_diameter_left_m"].get<double>() == Approx(0.084046).margin(1e-6));
  CHECK(j["evaluation"]["after"]["max_final_position_error_m"].get<double>() == Approx(0.007157).margin(1e-6));
  // c_R / c_L = E_d, corrected wheelbase = E_b * b (contract, precise points).
  CHECK(j["c_R"].get<double>() / j["c_L"].get<double>() == Approx(j["E_d"].get<double>()).epsilon(1e-12));
  CHECK(j["parameters"]["wheelbase_m"].get<double>() == Approx(0.2 * j["E_b"].get<double>()).epsilon(1e-12));
}

TEST_CASE("calibrate on endpoints equals calibrate on the trajectories they came from", "[cli]") {
  const auto a = RunCli("calibrate " + Q(kSrc / "data/examples/endpoints.csv") + " --robot " +
                        Q(kSrc / "data/examples/robot.toml") + " --side 0.75 --json -");
  const auto b = RunCli("calibrate " + Q(Imported() / "campaign.toml") + " --integrator midpoint --json -");
  REQUIRE(a.status == 0);
  REQUIRE(b.status == 0);
  const auto ja = nlohmann::json::parse(a.out), jb = nlohmann::json::parse(b.out);
  // endpoints.csv holds the return errors rounded to 1 micrometre.
  CHECK(ja["E_d"].get<double>() == Approx(jb["E_d"].get<double>()).margin(1e-6));
  CHECK(ja["E_b"].get<double>() == Approx(jb["E_b"].get<double>()).margin(1e-5));
  CHECK(ja["estimator"] == "mean");
}

TEST_CASE("evaluate --params applies a calibration and reproduces calibrate's after-measures", "[cli]") {
  const auto dir = TempDir("eval");
  const auto cal = RunCli("calibrate " + Q(Imported() / "campaign.toml") + " --json " + Q(dir / "cal.json"));
  REQUIRE(cal.status == 0);
  CHECK(cal.out.find("UMBmark calibration") != std::string::npos);  // text still on stdout
  const auto jc = nlohmann::json::parse(Slurp((dir / "cal.json").string()));
  const auto ev = RunCli("evaluate " + Q(Imported() / "campaign.toml") + " --params " + Q(dir / "cal.json") +
                         " --json - --plot " + Q(dir / "paths.svg"));
  REQUIRE(ev.status == 0);
  const auto je = nlohmann::json::parse(ev.out);
  REQUIRE(je["runs"].size() == 6);
  for (const auto& run : je["runs"]) {
    for (const char* key : {"final_position_error_m", "max_position_error_m", "final_heading_error_rad",
                            "max_heading_error_rad"})
      CHECK(run.at(key).get<double>() >= 0.0);
    CHECK(run.at("return_error").size() == 3);
  }
  CHECK(je["summary"]["max_max_position_error_m"].get<double>() ==
        Approx(jc["evaluation"]["after"]["max_max_position_error_m"].get<double>()).epsilon(1e-12));
  CHECK(je["summary"]["mean_final_heading_error_rad"].get<double>() ==
        Approx(jc["evaluation"]["after"]["mean_final_heading_error_rad"].get<double>()).epsilon(1e-12));
  CHECK(Slurp((dir / "paths.svg").string()).find("<svg") != std::string::npos);
}

TEST_CASE("calibrate --ros2 and --plot write their files", "[cli]") {
  const auto dir = TempDir("outputs");
  // --use classic: the multipliers are the classic result's (by default
  // --ros2 follows the held-out recommendation, tested in test_heldout).
  const auto r = RunCli("calibrate " + Q(Imported() / "campaign.toml") + " --use classic --ros2 " + Q(dir / "dd.yaml") +
                        " --plot " + Q(dir / "p.svg") + " --json " + Q(dir / "c.json"));
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(Slurp((dir / "c.json").string()));
  const std::string yaml = Slurp((dir / "dd.yaml").string());
  std::ostringstream eb;
  eb << "wheel_separation_multiplier: " << fmt::format("{}", j["E_b"].get<double>());
  CHECK(yaml.find(eb.str()) != std::string::npos);
  CHECK(yaml.find("left_wheel_radius_multiplier: " + fmt::format("{}", j["c_L"].get<double>())) != std::string::npos);
  CHECK(yaml.find("right_wheel_radius_multiplier: " + fmt::format("{}", j["c_R"].get<double>())) != std::string::npos);
  const std::string svg = Slurp((dir / "p.svg").string());
  CHECK(svg.find("After correction") != std::string::npos);
  // No temporary files left behind by the atomic writes.
  int files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files;
  CHECK(files == 3);
}

TEST_CASE("Exit status 2 for usage errors", "[cli]") {
  CHECK(RunCli("").status == 2);
  CHECK(RunCli("frobnicate").status == 2);
  CHECK(RunCli("calibrate " + Q(kGood / "endpoint_errors.csv") + " --robot " + Q(kGood / "robot.toml")).status == 2);  // no --side
  CHECK(RunCli("calibrate " + Q(kGood / "endpoint_errors.csv") + " --robot " + Q(kGood / "robot.toml") +
               " --side 1 --estimator z")
            .status == 2);
  CHECK(RunCli("calibrate " + Q(kGood / "endpoint_errors.csv") + " --side 1").status == 2);  // no robot
  CHECK(RunCli("calibrate " + Q(kGood / "endpoint_errors.csv") + " --robot " + Q(kGood / "robot.toml") +
               " --side -1")
            .status == 2);
  CHECK(RunCli("--help").status == 0);
}

TEST_CASE("Output to a device file is refused, exit 1", "[cli]") {
  const auto r = RunCli("calibrate " + Q(kGood / "endpoint_errors.csv") + " --robot " + Q(kGood / "robot.toml") +
                        " --side 1 --json /dev/null");
  CHECK(r.status == 1);
  CHECK(r.err.find("/dev/null") != std::string::npos);
}

TEST_CASE("Every file of the bad-input corpus exits 1 naming file, line and column", "[cli][bad-input]") {
  std::ifstream tsv(kBad / "EXPECTED.tsv");
  REQUIRE(tsv.good());
  std::string line;
  std::getline(tsv, line);  // header
  int n = 0;
  while (std::getline(tsv, line)) {
    std::stringstream ss(line);
    std::string file, kind, l, c, message;
    std::getline(ss, file, '\t');
    std::getline(ss, kind, '\t');
    std::getline(ss, l, '\t');
    std::getline(ss, c, '\t');
    std::getline(ss, message);
    const fs::path bad = kBad / file;
    std::string args;
    if (kind == "robot") {
      args = "calibrate " + Q(kGood / "endpoint_errors.csv") + " --side 1 --robot " + Q(bad);
    } else if (kind == "manifest") {
      args = "calibrate " + Q(bad);
    } else {
      args = "calibrate " + Q(bad) + " --side 1 --robot " + Q(kGood / "robot.toml");
    }
    const auto before = Slurp(bad.string());
    const auto r = RunCli(args);
    INFO(file << " (" << kind << "): " << r.err);
    CHECK(r.status == 1);
    // FILE:LINE:COLUMN: for a fault in a row, FILE:LINE: or FILE: otherwise.
    std::string prefix = bad.string() + ":";
    if (l != "0") prefix += l + ":";
    if (c != "0") prefix += c + ":";
    if (kind == "robot" || kind == "manifest") {
      CHECK(r.err.find(file) != std::string::npos);
    } else {
      CHECK(r.err.rfind(prefix, 0) == 0);
    }
    CHECK(Slurp(bad.string()) == before);  // input never modified
    ++n;
  }
  CHECK(n >= 20);
}

TEST_CASE("Batch: one result per input, a summary, exit 1 when one input fails", "[cli][batch]") {
  const auto dir = TempDir("batch");
  const auto r = RunCli("calibrate " + Q(kGood / "endpoint_errors.csv") + " " + Q(kSrc / "data/examples/endpoints.csv") +
                        " " + Q(kBad / "ep_inf.csv") + " --robot " + Q(kGood / "robot.toml") + " --side 0.75 --json " +
                        Q(dir / "batch.json"));
  CHECK(r.status == 1);
  CHECK(r.out.find("Summary (3 calibrations)") != std::string::npos);
  CHECK(r.err.find("ep_inf.csv:2:7:") != std::string::npos);
  const auto j = nlohmann::json::parse(Slurp((dir / "batch.json").string()));
  REQUIRE(j["results"].size() == 3);
  CHECK(j["results"][0].contains("E_d"));
  CHECK(j["results"][1].contains("E_b"));
  CHECK(j["results"][2].contains("error"));
  CHECK(j["failed"] == true);
}

TEST_CASE("A cw/ccw label that contradicts the ground truth is an input error", "[cli]") {
  const auto dir = TempDir("label");
  std::string text = Slurp((Imported() / "runs.csv").string());
  // Relabel run 1 (cw) as ccw.
  const std::string from = "\n1,cw,", to = "\n1,ccw,";
  for (std::size_t pos = text.find(from); pos != std::string::npos; pos = text.find(from, pos + to.size()))
    text.replace(pos, from.size(), to);
  std::ofstream(dir / "runs.csv") << text;
  fs::copy_file(Imported() / "campaign.toml", dir / "campaign.toml");
  const auto r = RunCli("calibrate " + Q(dir / "campaign.toml"));
  CHECK(r.status == 1);
  CHECK(r.err.find("run 1 is labelled ccw but its ground truth turns") != std::string::npos);
}

TEST_CASE("Runs in one direction only: exit 1 naming the file", "[cli][bad-input]") {
  const auto dir = TempDir("onedir");
  std::ofstream(dir / "cw_only.csv") << "run,direction,ex_m,ey_m,etheta_rad\n1,cw,0.01,0.02,\n2,cw,0.011,0.019,\n";
  const auto r = RunCli("calibrate " + Q(dir / "cw_only.csv") + " --robot " + Q(kGood / "robot.toml") + " --side 4");
  CHECK(r.status == 1);
  CHECK(r.err.rfind((dir / "cw_only.csv").string() + ": UMBmark needs runs in both directions", 0) == 0);
  // A direction that is not cw/ccw names the line.
  std::ofstream(dir / "bad_dir.csv") << "run,direction,ex_m,ey_m,etheta_rad\n1,cw,0.01,0.02,\n2,sideways,0.011,0.019,\n";
  const auto r2 = RunCli("calibrate " + Q(dir / "bad_dir.csv") + " --robot " + Q(kGood / "robot.toml") + " --side 4");
  CHECK(r2.status == 1);
  CHECK(r2.err.rfind((dir / "bad_dir.csv").string() + ":3:", 0) == 0);
}

TEST_CASE("calibrate --refine adds the contract's refined object", "[cli][refine]") {
  const auto r = RunCli("calibrate " + Q(Imported() / "campaign.toml") + " --refine --json -");
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.out);
  const auto& ref = j.at("refined");
  for (const char* key : {"wheelbase_m", "wheel_diameter_left_m", "wheel_diameter_right_m"}) {
    INFO(key);
    CHECK(ref.at("parameters").at(key).is_number());
    // The refined parameters are a correction of at most a few percent.
    CHECK(ref["parameters"][key].get<double>() == Approx(j["recorded_parameters"][key].get<double>()).epsilon(0.05));
  }
  REQUIRE(ref.at("covariance").size() == 3);
  for (int i = 0; i < 3; ++i) {
    REQUIRE(ref["covariance"][i].size() == 3);
    CHECK(ref["covariance"][i][i].get<double>() > 0.0);
    for (int k = 0; k < 3; ++k)
      CHECK(ref["covariance"][i][k].get<double>() == Approx(ref["covariance"][k][i].get<double>()).epsilon(1e-12));
  }
  CHECK(ref.at("final_cost").get<double>() >= 0.0);
  CHECK(ref.at("covariance_order") ==
        nlohmann::json({"wheelbase_m", "wheel_diameter_left_m", "wheel_diameter_right_m"}));
}

TEST_CASE("calibrate --refine --free scale on endpoint squares fails the quality gate (exit 3)", "[cli][refine]") {
  // Return errors of squares do not determine the mean wheel diameter.
  const auto r = RunCli("calibrate " + Q(kSrc / "data/examples/endpoints.csv") + " --robot " +
                        Q(kSrc / "data/examples/robot.toml") + " --side 0.75 --refine --free scale --json -");
  CHECK(r.status == 3);
  // The classic result still stands and is written; no refined numbers.
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j.at("parameters").at("wheelbase_m").is_number());
  CHECK_FALSE(j.contains("refined"));
  CHECK(j.at("refine_error").get<std::string>().find("scale") != std::string::npos);
  // The failure is said once.
  const auto first = r.err.find("refined calibration failed");
  REQUIRE(first != std::string::npos);
  CHECK(r.err.find("refined calibration failed", first + 1) == std::string::npos);
  // With the scale held (the default), the same data calibrate.
  const auto ok = RunCli("calibrate " + Q(kSrc / "data/examples/endpoints.csv") + " --robot " +
                         Q(kSrc / "data/examples/robot.toml") + " --side 0.75 --refine --json -");
  CHECK(ok.status == 0);
}

TEST_CASE("import optiodom takes the category from the parent folder, with or without a trailing slash", "[cli]") {
  const auto dir = TempDir("slash");
  const auto circ = kSrc / "data/optiodom-2020-06/circular/250620202317";
  const auto r = RunCli("import optiodom " + Q(circ.string() + "/") + " --out " + Q(dir) + " --json -");
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["category"] == "circular");
  CHECK(j["dataset"] == "250620202317");
}
