// Campaign simulator plumbing: seeds and reproducibility, the written files
// read back with the contract's readers, endpoint squares, replay of a free
// template, and the `umbmark simulate` command (campaign usable by calibrate
// and evaluate).
#include <catch2/catch.hpp>

#include <filesystem>
#include <variant>

#include <nlohmann/json.hpp>

#include "evaluation/return_error.hpp"
#include "formats/campaign_writer.hpp"
#include "formats/data_file.hpp"
#include "formats/manifest.hpp"
#include "formats/trajectory_csv.hpp"
#include "simulation/campaign_sim.hpp"
#include "support/run_cli.hpp"

using namespace umbmark;
using namespace umbmark::sim;
using Catch::Matchers::WithinAbs;

namespace {

RobotParams Robot() {
  RobotParams r;
  r.wheelbase_m = 0.3;
  r.wheel_diameter_left_m = 0.08;
  r.wheel_diameter_right_m = 0.081;
  r.ticks_per_rev = 2796.8;
  return r;
}

CampaignSimOptions Small() {
  CampaignSimOptions o;
  o.square_runs_per_direction = 2;
  o.back_and_forth_runs = 2;
  o.truth.E_d = 1.002;
  o.truth.E_b = 0.995;
  o.truth.k_L = 0.002;
  o.truth.k_R = 0.003;
  o.effects.bump_rate = 0.3;
  o.effects.bump_sigma = 0.003;
  return o;
}

Manifest SmallManifest() { return StandardCampaignManifest(Robot(), 1.0, 1.5, GroundTruthNoise{3e-4, 2e-3}); }

}  // namespace

TEST_CASE("simulate: same seed, same campaign; another seed, another", "[simulate]") {
  CampaignSimOptions o = Small();
  o.seed = 5;
  const SimulatedCampaign a = SimulateCampaign(SmallManifest(), o);
  const SimulatedCampaign b = SimulateCampaign(SmallManifest(), o);
  o.seed = 6;
  const SimulatedCampaign c = SimulateCampaign(SmallManifest(), o);
  const std::string ta = io::FormatTrajectoryCsv(std::get<TrajectoryData>(a.data[0]));
  CHECK(ta == io::FormatTrajectoryCsv(std::get<TrajectoryData>(b.data[0])));
  CHECK(ta != io::FormatTrajectoryCsv(std::get<TrajectoryData>(c.data[0])));
  CHECK(a.seed == 5);
  const nlohmann::json truth = CampaignTruthJson(a, Small());
  CHECK(truth["truth"]["E_d"] == 1.002);
  CHECK(truth["effects"][0]["effect"] == "bump_outliers");
  CHECK(truth["total_runs"] == 6);
}

TEST_CASE("simulate: a run does not depend on the other experiments", "[simulate]") {
  // Random streams are keyed by (seed, campaign run index): dropping the
  // back-and-forth experiment leaves the square runs bit for bit the same.
  CampaignSimOptions o = Small();
  Manifest m = SmallManifest();
  const SimulatedCampaign full = SimulateCampaign(m, o);
  m.experiments.pop_back();
  const SimulatedCampaign squares = SimulateCampaign(m, o);
  CHECK(io::FormatTrajectoryCsv(std::get<TrajectoryData>(full.data[0])) ==
        io::FormatTrajectoryCsv(std::get<TrajectoryData>(squares.data[0])));
}

TEST_CASE("simulate: files read back with the contract's readers", "[simulate]") {
  const auto dir = testing::TempDir("simulate");
  CampaignSimOptions o = Small();
  const SimulatedCampaign c = SimulateCampaign(SmallManifest(), o);
  const std::string manifest_path = io::WriteCampaign(c.manifest, c.data, dir.string());
  const Manifest m = io::ReadManifest(manifest_path);
  REQUIRE(m.experiments.size() == 2);
  REQUIRE(m.ground_truth);
  CHECK(m.ground_truth->sigma_xy_m == 3e-4);
  CHECK(*m.robot.ticks_per_rev == 2796.8);
  for (std::size_t e = 0; e < 2; ++e) {
    const TrajectoryData back = io::ReadTrajectoryCsv(m.experiments[e].resolved_file);
    const auto& orig = std::get<TrajectoryData>(c.data[e]);
    REQUIRE(back.runs.size() == orig.runs.size());
    for (std::size_t r = 0; r < back.runs.size(); ++r) {
      CHECK(back.runs[r].ticks_left == orig.runs[r].ticks_left);
      CHECK(back.runs[r].ticks_right == orig.runs[r].ticks_right);
      CHECK(back.runs[r].gt_x_m == orig.runs[r].gt_x_m);
      CHECK(back.runs[r].gt_theta_rad == orig.runs[r].gt_theta_rad);
      CHECK(back.runs[r].t_s == orig.runs[r].t_s);
    }
  }
}

TEST_CASE("simulate: endpoint squares are the trajectories' return errors", "[simulate]") {
  CampaignSimOptions o = Small();
  const SimulatedCampaign traj = SimulateCampaign(SmallManifest(), o);
  o.endpoint_squares = true;
  const SimulatedCampaign ep = SimulateCampaign(SmallManifest(), o);
  REQUIRE(std::holds_alternative<EndpointData>(ep.data[0]));
  const auto errors =
      ReturnErrorsFromTrajectories(std::get<TrajectoryData>(traj.data[0]), Robot(), Robot(), Integrator::kArc);
  const auto& runs = std::get<EndpointData>(ep.data[0]).runs;
  REQUIRE(runs.size() == errors.size());
  for (std::size_t i = 0; i < runs.size(); ++i) {
    CHECK(runs[i].direction == errors[i].direction);
    CHECK(runs[i].ex_m == errors[i].ex_m);
    CHECK(runs[i].ey_m == errors[i].ey_m);
  }
  const auto dir = testing::TempDir("simulate-ep");
  const std::string path = io::WriteCampaign(ep.manifest, ep.data, dir.string());
  const Manifest m = io::ReadManifest(path);
  const io::RunFile rf = io::ReadRunFile(m.experiments[0].resolved_file);
  REQUIRE(std::holds_alternative<EndpointData>(rf));
  CHECK(std::get<EndpointData>(rf).runs.size() == runs.size());
  CHECK_THAT(std::get<EndpointData>(rf).runs[1].ex_m, WithinAbs(runs[1].ex_m, 0.0));
}

TEST_CASE("simulate: a free template is replayed from its ticks", "[simulate]") {
  // A figure-eight campaign serves as the template; replaying it on the same
  // noise-free nominal robot reproduces its encoder counts and ground truth.
  CampaignSimOptions o;
  o.truth.k_L = o.truth.k_R = 0.0;
  o.ground_truth = GroundTruthNoise{0.0, 0.0};
  o.free_runs = 1;
  Manifest m;
  m.robot = Robot();
  Experiment fr;
  fr.kind = ExperimentKind::kFree;
  fr.file = "free.csv";
  m.experiments = {fr};
  const SimulatedCampaign generated = SimulateCampaign(m, o);
  const auto& tmpl = std::get<TrajectoryData>(generated.data[0]);
  const SimulatedCampaign replayed = SimulateCampaign(m, o, {tmpl});
  const auto& again = std::get<TrajectoryData>(replayed.data[0]);
  REQUIRE(again.runs.size() == 1);
  const auto& a = tmpl.runs[0];
  const auto& b = again.runs[0];
  REQUIRE(a.size() == b.size());
  std::int64_t max_tick_diff = 0;
  double max_pos_diff = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    max_tick_diff = std::max(max_tick_diff, std::abs(a.ticks_left[i] - b.ticks_left[i]));
    max_tick_diff = std::max(max_tick_diff, std::abs(a.ticks_right[i] - b.ticks_right[i]));
    max_pos_diff = std::max(max_pos_diff, std::hypot(a.gt_x_m[i] - b.gt_x_m[i], a.gt_y_m[i] - b.gt_y_m[i]));
  }
  // Counts agree to a tick (different encoder start phases); the path to the
  // travel of a tick or two per sample interval.
  CHECK(max_tick_diff <= 1);
  CHECK(max_pos_diff < 2e-3);
}

TEST_CASE("simulate: parameter_drift that would make a diameter negative is rejected", "[simulate]") {
  CampaignSimOptions o = Small();
  o.effects.drift_r = -0.09;  // 6 runs: 1 - 0.09 * 5 > 0 is fine
  CHECK_NOTHROW(SimulateCampaign(SmallManifest(), o));
  o.square_runs_per_direction = 10;  // 22 runs: 1 - 0.09 * 21 < 0
  CHECK_THROWS_AS(SimulateCampaign(SmallManifest(), o), InvalidOptions);
}

TEST_CASE("umbmark simulate: writes a campaign calibrate and evaluate accept", "[simulate][cli]") {
  using testing::Q;
  const auto dir = testing::TempDir("simulate-cli");
  const auto in = dir / "in.toml";
  {
    std::ofstream f(in);
    f << "[robot]\nwheelbase_m = 0.3\nwheel_diameter_left_m = 0.08\nwheel_diameter_right_m = 0.08\n"
         "ticks_per_rev = 2000\n\n[ground_truth]\nsigma_xy_m = 0.0003\nsigma_theta_rad = 0.002\n\n"
         "[[experiment]]\nkind = \"square\"\nside_m = 1.0\nfile = \"sq.csv\"\n\n"
         "[[experiment]]\nkind = \"back_and_forth\"\ndistance_m = 1.0\nfile = \"bf.csv\"\n";
  }
  const auto out = dir / "out";
  auto r = testing::RunCli("simulate " + Q(in) + " --out " + Q(out) +
                           " --E-d 1.004 --E-b 1.01 --square-runs 3 --back-and-forth-runs 2"
                           " --effect turn_scrub:k=0.02 --seed 9 --truth-out " + Q(dir / "truth.json") +
                           " --json " + Q(dir / "sim.json"));
  INFO(r.err);
  REQUIRE(r.status == 0);
  const auto truth = nlohmann::json::parse(testing::Slurp((dir / "truth.json").string()));
  CHECK(truth["seed"] == 9);
  CHECK(truth["effects"][0]["effect"] == "turn_scrub");
  CHECK(truth["effects"][0]["params"]["k"] == 0.02);
  CHECK_FALSE(std::filesystem::exists(out / "truth.json"));
  const std::string manifest = (out / "campaign.toml").string();
  CHECK(testing::Slurp(manifest).find("turn_scrub") == std::string::npos);  // blind: no truth inside

  r = testing::RunCli("calibrate " + Q(manifest) + " --json -");
  INFO(r.err);
  REQUIRE(r.status == 0);
  const auto cal = nlohmann::json::parse(r.out);
  CHECK(cal.dump().find("E_d") != std::string::npos);
  r = testing::RunCli("evaluate " + Q(manifest) + " --json -");
  INFO(r.err);
  CHECK(r.status == 0);

  // Usage errors: an unknown effect, a bad parameter.
  r = testing::RunCli("simulate " + Q(in) + " --out " + Q(dir / "x") + " --effect warp:x=1");
  CHECK(r.status == 2);
  CHECK(r.err.find("unknown effect") != std::string::npos);
  r = testing::RunCli("simulate " + Q(in) + " --out " + Q(dir / "x") + " --effect correlated_noise:rho=2");
  CHECK(r.status == 2);
}
