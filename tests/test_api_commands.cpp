// The library API of the commands (lib/api, installed as include/umbmark/):
// calibrate-lidar, evaluate, fit-noise, import, plan and summarize called as functions give the
// command line's JSON key for key and number for number (the JSON of a
// separate `umbmark` process), their options name the bad field, and the
// numbers they return agree with what follows from them (a summary is the
// mean and maximum of its runs).
#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <string>

#include "api/calibrate_lidar.hpp"
#include "api/evaluate.hpp"
#include "api/fit_noise.hpp"
#include "api/import.hpp"
#include "api/plan.hpp"
#include "api/summarize.hpp"
#include "core/errors.hpp"
#include "formats/robot_toml.hpp"
#include "support/run_cli.hpp"

using namespace umbmark;
using umbmark::testing::Q;
using umbmark::testing::RunCli;
using umbmark::testing::Slurp;
using umbmark::testing::TempDir;
namespace fs = std::filesystem;

namespace {

const fs::path kSrc = UMBMARK_SOURCE_DIR;
const fs::path kEx = kSrc / "data/examples";
const fs::path kBags = kSrc / "tests/data/rosbag2";

nlohmann::json Cli(const std::string& args) {
  const auto r = RunCli(args + " --json -");
  REQUIRE(r.status == 0);
  return nlohmann::json::parse(r.out);
}

// What the command line writes: the result's JSON as text and back (the
// same doubles: both print shortest round-trip decimals).
nlohmann::json RoundTrip(const nlohmann::json& j) { return nlohmann::json::parse(j.dump()); }

}  // namespace

TEST_CASE("api::Evaluate gives evaluate's JSON; its summary is the mean and maximum of its runs", "[api]") {
  api::EvaluateOptions o;
  o.inputs = {(kEx / "square_ticks.csv").string()};
  o.robot.robot_file = (kEx / "robot.toml").string();
  const api::EvaluateResult r = api::Evaluate(o);
  CHECK(RoundTrip(api::ToJson(r)) ==
        Cli("evaluate " + Q(kEx / "square_ticks.csv") + " --robot " + Q(kEx / "robot.toml")));
  REQUIRE(r.summary.runs.size() >= 4);
  double sum = 0.0, worst = 0.0;
  for (const auto& run : r.summary.runs) {
    sum += run.final_position_error_m;
    worst = std::max(worst, run.max_position_error_m);
  }
  CHECK(r.summary.mean_final_position_error_m == Approx(sum / static_cast<double>(r.summary.runs.size())).epsilon(1e-14));
  CHECK(r.summary.max_max_position_error_m == worst);
  CHECK_FALSE(r.recorded);
  CHECK(r.parameters.wheelbase_m == io::ReadRobotToml(o.robot.robot_file).wheelbase_m);

  api::EvaluateOptions bad;
  CHECK_THAT(bad.Check(), Catch::StartsWith("inputs:"));
  bad = o;
  bad.robot.wheelbase_m = -0.2;
  CHECK_THAT(bad.Check(), Catch::StartsWith("--wheelbase"));
  CHECK_THROWS_AS(api::Evaluate(bad), InvalidOptions);
}

TEST_CASE("api::FitNoise gives fit-noise's JSON; its options name the bad field", "[api]") {
  api::FitNoiseOptions o;
  o.inputs = {(kEx / "fit-noise.toml").string()};
  const api::FitNoiseResult r = api::FitNoise(o);
  CHECK(RoundTrip(api::ToJson(r)) == Cli("fit-noise " + Q(kEx / "fit-noise.toml")));
  CHECK(r.inputs == std::vector<std::string>{(kEx / "fwd_back_travel.csv").string()});
  CHECK(r.fit.runs == static_cast<int>(r.fit.group_of_run.size()));
  CHECK(r.restricted);
  CHECK(r.second_order);
  CHECK_FALSE(r.ros2);

  api::FitNoiseOptions bad = o;
  bad.meas_sigma = {0.001, 0.002, 0.003};
  CHECK_THAT(bad.Check(), Catch::StartsWith("--meas-sigma"));
  bad = o;
  bad.systematic = "guess";
  CHECK_THAT(bad.Check(), Catch::Contains("systematic = 'guess'"));
  bad = o;
  bad.ros2_file = "cov.yaml";
  bad.covariance.rate_hz = 0.0;
  CHECK_THAT(bad.Check(), Catch::StartsWith("rate_hz"));
}

TEST_CASE("api::ImportRosbag2 writes the campaign the command writes and gives its JSON", "[api][rosbag2]") {
  const fs::path dir = TempDir("api-import");
  const std::string bag = (kBags / "square_run1.mcap").string();
  api::ImportRosbag2Options o;
  o.bags = {bag};
  o.robot = io::ReadRobotToml((kBags / "robot.toml").string());
  o.import.kind = ExperimentKind::kSquare;
  o.import.side_m = 0.75;
  o.import.wheels_topic = "/joint_states";
  o.import.ground_truth_topic = "/mocap/pose";
  o.import.pause_s = 0.0;
  o.out = (dir / "api").string();
  const api::ImportRosbag2Result r = api::ImportRosbag2(o);
  nlohmann::json cli = Cli("import rosbag2 " + Q(bag) + " --out " + Q(dir / "cli") + " --experiment square --side 0.75 "
                           "--robot " + Q(kBags / "robot.toml") + " --wheels /joint_states --ground-truth /mocap/pose "
                           "--pause 0");
  nlohmann::json api_json = RoundTrip(api::ToJson(r));
  CHECK(api_json["manifest"] == (dir / "api" / "campaign.toml").string());
  for (auto* j : {&cli, &api_json}) {
    j->erase("manifest");
    j->erase("runs_csv");
  }
  // The warnings name the runs.csv they are about: the one of each folder.
  std::string api_text = api_json.dump();
  const std::string api_csv = (dir / "api" / "runs.csv").string(), cli_csv = (dir / "cli" / "runs.csv").string();
  for (std::size_t at = api_text.find(api_csv); at != std::string::npos; at = api_text.find(api_csv, at))
    api_text.replace(at, api_csv.size(), cli_csv);
  CHECK(nlohmann::json::parse(api_text) == cli);
  CHECK(Slurp((dir / "api" / "runs.csv").string()) == Slurp((dir / "cli" / "runs.csv").string()));
  CHECK(Slurp((dir / "api" / "campaign.toml").string()) == Slurp((dir / "cli" / "campaign.toml").string()));
  REQUIRE(r.imported.runs.runs.size() == 1);
  CHECK(r.imported.runs.runs[0].direction == "cw");

  api::ImportRosbag2Options bad = o;
  bad.out.clear();
  CHECK_THAT(bad.Check(), Catch::StartsWith("--out"));
  bad = o;
  bad.import.side_m = 0.0;
  CHECK_THAT(bad.Check(), Catch::StartsWith("side_m"));
}

TEST_CASE("api::Summarize gives summarize's JSON and CSV", "[api][fleet]") {
  const fs::path dir = TempDir("api-summarize");
  std::vector<std::string> files;
  for (const char* est : {"mean", "x", "mean"}) {
    files.push_back((dir / (std::string("cal-") + std::to_string(files.size()) + ".json")).string());
    REQUIRE(RunCli("calibrate " + Q(kEx / "calibrate.toml") + " --estimator " + est + " --json " + Q(files.back())).status == 0);
  }
  api::SummarizeOptions o;
  o.inputs = files;
  const api::SummarizeResult r = api::Summarize(o);
  std::string args = "summarize";
  for (const auto& f : files) args += " " + Q(f);
  CHECK(RoundTrip(api::ToJson(r)) == Cli(args + " --csv " + Q(dir / "fleet.csv")));
  CHECK(api::SummarizeCsv(r) == Slurp((dir / "fleet.csv").string()));
  REQUIRE(r.robots.size() == 3);
  CHECK(r.robots[0].robot == "cal-0");
  CHECK(r.files == 3);

  api::SummarizeOptions bad = o;
  bad.fleet.threshold = -1.0;
  CHECK_THAT(bad.Check(), Catch::Contains("threshold"));
  CHECK_THROWS_AS(api::Summarize(bad), InvalidOptions);
}

TEST_CASE("api::Plan gives plan's JSON and motions, api::PlanCheck plan --check's JSON", "[api][plan]") {
  const fs::path dir = TempDir("api-plan");
  api::PlanOptions o;
  o.robot.robot_file = (kEx / "robot.toml").string();
  o.noise.k_L = 1e-3;
  o.noise.k_R = 8e-4;
  o.target_E_d = 5e-4;
  o.target_E_b = 2e-3;
  o.target_k = 2e-4;
  o.max_side_m = 2.0;
  const api::PlanResult r = api::Plan(o);
  CHECK(RoundTrip(api::ToJson(r)) ==
        Cli("plan --robot " + Q(kEx / "robot.toml") + " --kl 1e-3 --kr 8e-4 --target-E_d 5e-4 --target-E_b 2e-3 "
            "--target-k 2e-4 --max-side 2 --motions " + Q(dir / "cli-motions.json")));
  api::WritePlanMotions(r, (dir / "api-motions.json").string());
  CHECK(Slurp((dir / "api-motions.json").string()) == Slurp((dir / "cli-motions.json").string()));
  // Every targeted quantity is met, and the one that binds is a target.
  for (const auto& [name, target] : r.targets) {
    INFO(name);
    REQUIRE(r.predicted_ci95.at(name));
    CHECK(*r.predicted_ci95.at(name) <= target);
  }
  CHECK(r.targets.size() == 4);  // E_d, E_b, k_L, k_R (--target-k is both wheels)
  CHECK(r.design.square_side_m <= 2.0);

  api::PlanOptions bad = o;
  bad.noise.noise_file = "fit.json";
  CHECK_THAT(bad.Check(), Catch::Contains("not both"));
  bad = o;
  bad.noise.k_R.reset();
  CHECK_THAT(bad.Check(), Catch::Contains("wheel noise is needed"));
  bad = o;
  bad.ground_truth = "laser";
  CHECK_THAT(bad.Check(), Catch::StartsWith("--ground-truth"));
  bad = o;
  bad.timing.speed_m_s = 0.0;
  CHECK_THAT(bad.Check(), Catch::StartsWith("--speed"));
  CHECK_THROWS_AS(api::Plan(bad), InvalidOptions);

  api::PlanCheckOptions c;
  c.manifest = (kEx / "calibrate.toml").string();
  c.noise.k_L = 2.29e-4;
  c.noise.k_R = 1.15e-3;
  const api::PlanCheckResult cr = api::PlanCheck(c);
  CHECK(RoundTrip(api::ToJson(cr)) == Cli("plan --check " + Q(kEx / "calibrate.toml") + " --kl 2.29e-4 --kr 1.15e-3"));
  CHECK(cr.k_L == 2.29e-4);
  CHECK_FALSE(cr.noise_fitted);
  CHECK(cr.square_runs_cw + cr.square_runs_ccw > 0);
  api::PlanCheckOptions bad_check = c;
  bad_check.manifest = (kEx / "square_ticks.csv").string();
  CHECK_THAT(bad_check.Check(), Catch::StartsWith("--check"));
  bad_check = c;
  bad_check.noise.k_R.reset();
  CHECK_THAT(bad_check.Check(), Catch::Contains("--kl and --kr go together"));
}

TEST_CASE("api::CalibrateLidar gives calibrate-lidar's JSON and --ros2 file", "[api][lidar]") {
  const fs::path dir = TempDir("api-calibrate-lidar");
  const fs::path lidar = kBags / "lidar";
  api::CalibrateLidarOptions o;
  o.bags = {(lidar / "drive_upside.mcap").string()};
  o.robot = io::ReadRobotToml((lidar / "robot.toml").string());
  o.read.scan_topic = "/scan";
  o.read.wheels_topic = "/joint_states";
  o.read.imu_topic = "/imu";
  const api::CalibrateLidarResult r = api::CalibrateLidar(o);
  CHECK(RoundTrip(api::ToJson(r)) ==
        Cli("calibrate-lidar " + Q(lidar / "drive_upside.mcap") + " --scan /scan --wheels /joint_states --imu /imu --robot " +
            Q(lidar / "robot.toml") + " --ros2 " + Q(dir / "cli.yaml")));
  api::WriteCalibrateLidarRos2(r, (dir / "api.yaml").string());
  CHECK(Slurp((dir / "api.yaml").string()) == Slurp((dir / "cli.yaml").string()));
  CHECK_FALSE(r.refused);
  CHECK(r.calibration.upside_down);
  REQUIRE(r.calibration.gyro_scale);
  // The ROS 2 multipliers are the fitted parameters over the recorded ones.
  CHECK(r.calibration.wheel_separation_multiplier == Approx(r.calibration.parameters.wheelbase_m / o.robot.wheelbase_m));

  api::CalibrateLidarOptions bad = o;
  bad.read.odometry_topic = "/odom";
  CHECK_THAT(bad.Check(), Catch::Contains("exactly one wheel source"));
  bad = o;
  bad.bags.clear();
  CHECK_THAT(bad.Check(), Catch::StartsWith("bags:"));
  bad = o;
  bad.distance_m = -3.0;
  CHECK_THAT(bad.Check(), Catch::StartsWith("--distance-m"));
  CHECK_THROWS_AS(api::CalibrateLidar(bad), InvalidOptions);
}
