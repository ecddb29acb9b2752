// `umbmark fit-noise` end to end: endpoint CSV with --distance, the same
// runs as a trajectory CSV (path from the wheel travel, return error from
// ground truth at both ends), a campaign manifest, the JSON keys of the
// contract, the SVG plot, and the exit codes.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "support/run_cli.hpp"
#include "report/html_report.hpp"

#include "core/angles.hpp"
#include "error_models/path_spec.hpp"
#include "simulation/monte_carlo_kernel.hpp"

using namespace umbmark;
namespace fs = std::filesystem;

namespace {

testing::CliResult Run(const std::string& args) { return testing::RunCli(args); }

void Write(const fs::path& p, const std::string& text) {
  std::ofstream f(p);
  f << text;
}

/// 60 simulated runs of 10 m forward and back (k_L = 0.0004, k_R = 0.00058,
/// b = 0.371), written both as an endpoint CSV and as a trajectory CSV.
struct Campaign {
  fs::path dir, robot, endpoint, trajectory, manifest;
};

Campaign MakeCampaign() {
  Campaign c;
  c.dir = fs::temp_directory_path() / fmt::format("umbmark_fit_noise_cli_{}", ::getpid());
  fs::create_directories(c.dir);
  c.robot = c.dir / "robot.toml";
  Write(c.robot, "wheelbase_m = 0.371\nwheel_diameter_left_m = 0.1\nwheel_diameter_right_m = 0.1\n");
  sim::SimulationModel m;
  m.nominal.wheelbase_m = 0.371;
  m.nominal.wheel_diameter_left_m = m.nominal.wheel_diameter_right_m = 0.1;
  m.noise = {0.00040, 0.00058};
  const auto path = ToWheelSegments(BackAndForthPath(10.0), 0.371);
  const int P = 100;
  const sim::SimPlan plan = sim::CompilePlan(m, path, P);
  const auto traces = sim::SimulateTraces(plan, 77, 0, 60, 10);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> N01;
  const double sxy = 0.0005, sth = 0.0017;
  std::string ep = "run,direction,ex_m,ey_m,etheta_rad\n";
  std::string tr = "run,direction,t_s,dist_left_m,dist_right_m,x_gt_m,y_gt_m,theta_gt_rad\n";
  for (const auto& t : traces) {
    const Pose2 gs{sxy * N01(rng), sxy * N01(rng), sth * N01(rng)};
    const Pose2 te = t.truth.back();
    const Pose2 ge{te.x + sxy * N01(rng), te.y + sxy * N01(rng), te.theta + sth * N01(rng)};
    const Pose2 rel = RelativeTo(gs, ge);
    ep += fmt::format("{},fwd_back,{:.17g},{:.17g},{:.17g}\n", t.run + 1, rel.x, rel.y, WrapAngle(rel.theta));
    // Trajectory: commanded wheel travel at every recorded sample; ground
    // truth (world frame, arbitrary origin) only at the first and last.
    const Pose2 origin{2.0, -1.0, 0.7};
    const Pose2 w0 = Compose(origin, gs), w1 = Compose(origin, ge);
    tr += fmt::format("{},fwd_back,0,0,0,{:.17g},{:.17g},{:.17g}\n", t.run + 1, w0.x, w0.y, w0.theta);
    for (std::size_t i = 0; i < t.truth.size(); ++i) {
      const double s = t.segment[i] == 0 ? 10.0 * t.partition[i] / P : 10.0 - 10.0 * t.partition[i] / P;
      const bool last = i + 1 == t.truth.size();
      tr += fmt::format("{},fwd_back,{},{:.17g},{:.17g},{},{},{}\n", t.run + 1, 0.1 * static_cast<double>(i + 1), s, s,
                        last ? fmt::format("{:.17g}", w1.x) : "", last ? fmt::format("{:.17g}", w1.y) : "",
                        last ? fmt::format("{:.17g}", w1.theta) : "");
    }
  }
  c.endpoint = c.dir / "fwd_back.csv";
  c.trajectory = c.dir / "fwd_back_traj.csv";
  Write(c.endpoint, ep);
  Write(c.trajectory, tr);
  c.manifest = c.dir / "campaign.toml";
  Write(c.manifest,
        "[robot]\nwheelbase_m = 0.371\nwheel_diameter_left_m = 0.1\nwheel_diameter_right_m = 0.1\n\n"
        "[ground_truth]\nsigma_xy_m = 0.0005\nsigma_theta_rad = 0.0017\n\n"
        "[[experiment]]\nkind = \"back_and_forth\"\ndistance_m = 10.0\nfile = \"fwd_back.csv\"\n");
  return c;
}

}  // namespace

TEST_CASE("fit-noise CLI: endpoint, trajectory and manifest inputs agree; contract keys; plot", "[fit_noise_cli]") {
  const Campaign c = MakeCampaign();
  const fs::path svg = c.dir / "fig4.svg";
  const auto ep = Run(fmt::format("fit-noise {} --robot {} --distance 10 --meas-sigma 0.0005,0.0017 --json - --plot {}",
                                    c.endpoint.string(), c.robot.string(), svg.string()));
  REQUIRE(ep.status == 0);
  const auto j = nlohmann::json::parse(ep.out);
  for (const char* key : {"k_L", "k_R", "k_L_ci95", "k_R_ci95"}) CHECK(j.contains(key));
  const double kL = j["k_L"], kR = j["k_R"];
  CHECK(kL == Approx(0.00040).epsilon(0.35));
  CHECK(kR == Approx(0.00058).epsilon(0.35));
  CHECK(j["k_L_ci95"][0].get<double>() < kL);
  CHECK(j["k_L_ci95"][1].get<double>() > kL);
  CHECK(j["runs"] == 60);
  CHECK(j["goodness_of_fit"].size() == 6);
  // The plot has three panels with two ellipses each.
  std::ifstream f(svg);
  const std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  CHECK(text.find("<svg") != std::string::npos);
  CHECK(text.find("e_theta [mrad]") != std::string::npos);

  // Same runs as a trajectory CSV: the path comes from the wheel travel.
  // First order: Kelly's form along the samples equals the closed form.
  const auto ep1 = Run(fmt::format("fit-noise {} --robot {} --distance 10 --meas-sigma 0.0005,0.0017 --first-order "
                                     "--json -",
                                     c.endpoint.string(), c.robot.string()));
  const auto tr1 = Run(fmt::format("fit-noise {} --robot {} --meas-sigma 0.0005,0.0017 --first-order --json -",
                                     c.trajectory.string(), c.robot.string()));
  REQUIRE(tr1.status == 0);
  const auto je1 = nlohmann::json::parse(ep1.out), jt1 = nlohmann::json::parse(tr1.out);
  CHECK(jt1["k_L"].get<double>() == Approx(je1["k_L"].get<double>()).epsilon(1e-6));
  CHECK(jt1["k_R"].get<double>() == Approx(je1["k_R"].get<double>()).epsilon(1e-6));
  // Default (with the second-order term): the trajectory's 10 samples per
  // leg evaluate that term by a coarser midpoint rule than the closed path.
  const auto tr = Run(fmt::format("fit-noise {} --robot {} --meas-sigma 0.0005,0.0017 --json -",
                                    c.trajectory.string(), c.robot.string()));
  REQUIRE(tr.status == 0);
  const auto jt = nlohmann::json::parse(tr.out);
  CHECK(jt["k_L"].get<double>() == Approx(kL).epsilon(1e-3));
  CHECK(jt["k_R"].get<double>() == Approx(kR).epsilon(1e-3));

  // Manifest: reference noise from [ground_truth], path from distance_m.
  const auto mf = Run(fmt::format("fit-noise {} --json -", c.manifest.string()));
  REQUIRE(mf.status == 0);
  const auto jm = nlohmann::json::parse(mf.out);
  CHECK(jm["k_L"].get<double>() == Approx(kL).epsilon(1e-9));
  CHECK(jm["groups"][0]["group"] == "exp1:back_and_forth:fwd_back");

  // Human-readable output names the goodness-of-fit table.
  const auto text_out = Run(fmt::format("fit-noise {} --robot {} --distance 10", c.endpoint.string(), c.robot.string()));
  CHECK(text_out.status == 0);
  CHECK(text_out.out.find("Goodness of fit") != std::string::npos);
  if (!std::getenv("UMBMARK_KEEP_TEST_FILES")) fs::remove_all(c.dir);
}

TEST_CASE("fit-noise CLI: the HTML report shows the warnings and notes the text and JSON give",
          "[fit_noise_cli][report]") {
  // Trajectories with ground truth but no --meas-sigma: the reference-noise
  // warning; back-and-forth runs only (no turns): the E_b note.
  const Campaign c = MakeCampaign();
  const fs::path html = c.dir / "fn.html", json = c.dir / "fn.json";
  const auto r = Run(fmt::format("fit-noise {} --robot {} --json {} --report {}", c.trajectory.string(),
                                 c.robot.string(), json.string(), html.string()));
  REQUIRE(r.status == 0);
  std::ifstream jf(json);
  const nlohmann::json j = nlohmann::json::parse(jf);
  std::ifstream hf(html);
  const std::string page((std::istreambuf_iterator<char>(hf)), std::istreambuf_iterator<char>());
  REQUIRE(j["warnings"].size() >= 1);
  REQUIRE(j["notes"].size() >= 1);
  CHECK(j["warnings"][0].get<std::string>().find("reference noise is 0") != std::string::npos);
  CHECK(j["notes"][0].get<std::string>().find("does not show E_b") != std::string::npos);
  CHECK(page.find("<h2>Warnings</h2>") != std::string::npos);
  CHECK(page.find("<h2>Notes</h2>") != std::string::npos);
  for (const auto& w : j["warnings"]) {
    CHECK(page.find(io::HtmlEscape(w.get<std::string>())) != std::string::npos);
    CHECK(r.out.find("WARNING: " + w.get<std::string>()) != std::string::npos);
  }
  for (const auto& n : j["notes"]) {
    CHECK(page.find(io::HtmlEscape(n.get<std::string>())) != std::string::npos);
    CHECK(r.out.find("note: " + n.get<std::string>()) != std::string::npos);
  }
  if (!std::getenv("UMBMARK_KEEP_TEST_FILES")) fs::remove_all(c.dir);
}

TEST_CASE("fit-noise CLI exit codes", "[fit_noise_cli]") {
  const Campaign c = MakeCampaign();
  // Endpoint data without --distance: usage error.
  CHECK(Run(fmt::format("fit-noise {} --robot {}", c.endpoint.string(), c.robot.string())).status == 2);
  // Unknown flag / bad --meas-sigma.
  CHECK(Run(fmt::format("fit-noise {} --robot {} --distance -1", c.endpoint.string(), c.robot.string())).status == 2);
  CHECK(Run(fmt::format("fit-noise {} --robot {} --distance 10 --meas-sigma 1,2,3", c.endpoint.string(),
                        c.robot.string()))
            .status == 2);
  // Bad data: a text cell.
  const fs::path bad = c.dir / "bad.csv";
  Write(bad, "run,direction,ex_m,ey_m,etheta_rad\n1,fwd_back,0.001,abc,0.0\n2,fwd_back,0.0,0.0,0.0\n");
  CHECK(Run(fmt::format("fit-noise {} --robot {} --distance 10", bad.string(), c.robot.string())).status == 1);
  // Too few runs to identify the model: bad data (1).
  const fs::path few = c.dir / "few.csv";
  Write(few, "run,direction,ex_m,ey_m,etheta_rad\n1,fwd_back,0.001,0.01,0.001\n2,fwd_back,0.0,0.0,0.0\n");
  CHECK(Run(fmt::format("fit-noise {} --robot {} --distance 10", few.string(), c.robot.string())).status == 1);
  // A group with a single run, in the second of two files: the message
  // names that file and the run's line (not "<input>" or the first file).
  const fs::path lone = c.dir / "lone.csv";
  Write(lone, "run,direction,ex_m,ey_m,etheta_rad\n1,a,0.001,0.01,0.001\n2,a,0.0,0.0,0.0\n3,a,0.002,0.01,0.002\n"
              "4,b,0.0,0.0,0.0\n");
  const auto single = Run(fmt::format("fit-noise {} {} --robot {} --distance 10", c.endpoint.string(), lone.string(),
                                      c.robot.string()));
  CHECK(single.status == 1);
  CHECK(single.err.find(lone.string() + ":5: run 4 is the only run of group") != std::string::npos);
  CHECK(single.err.find("<input>") == std::string::npos);
  // Runs without any scatter and no measurement noise: every wheel-noise
  // covariance is singular, so the fit cannot start -- the quality gate
  // (exit 3), not a number.
  const fs::path same = c.dir / "same.csv";
  std::string rows = "run,direction,ex_m,ey_m,etheta_rad\n";
  for (int i = 1; i <= 4; ++i) rows += fmt::format("{},fwd_back,0.001,0.002,0.001\n", i);
  Write(same, rows);
  const auto gate =
      Run(fmt::format("fit-noise {} --robot {} --distance 10 --meas-sigma 0,0 --json -", same.string(), c.robot.string()));
  CHECK(gate.status == 3);
  CHECK(gate.out.empty());
  CHECK(gate.err.find("quality gate") != std::string::npos);
  CHECK(gate.err.find("singular") != std::string::npos);
  fs::remove_all(c.dir);
}
