// fit-noise on robots with uncorrected systematic errors: k_L, k_R must be
// unbiased whether or not the robot was calibrated. Monte Carlo over 200
// independently simulated campaigns (simulation/monte_carlo_kernel, which
// shares no code with the fit's closed-form covariance) with E_d drawn in
// [0.99, 1.01] and E_b in [0.97, 1.03]: 60 runs of 10 m forward and back
// (Chong & Kleeman section 6.3, k_L = 0.0004, k_R = 0.00058 m^1/2), the
// reference measuring start and end with 0.5 mm / 0.1 deg noise.
// Measured over 1000 campaigns by bench/fit_noise_coverage.sh (table in
// docs/noise-model.md); here 400 with a binomial tolerance (below).
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/angles.hpp"
#include "error_models/path_spec.hpp"
#include "error_models/wheel_noise_fit.hpp"
#include "error_models/wheel_noise_fit_data.hpp"
#include "simulation/monte_carlo_kernel.hpp"
#include "support/fit_noise_campaign.hpp"
#include "support/run_cli.hpp"

using namespace umbmark;

namespace {

using testing::kB;
using testing::kTrueKL;
using testing::kTrueKR;

EndpointData Simulate(const std::vector<PathSegment>& spec, double E_d, double E_b, int n, std::uint64_t seed,
                      const std::string& direction) {
  return testing::SimulateReturnErrors(spec, E_d, E_b, n, seed, direction);
}

struct Tally {
  int cover_L = 0, cover_R = 0, n = 0;
  double sum_L = 0.0, sum_R = 0.0;
  void Add(const WheelNoiseFitSummary& s) {
    cover_L += s.k_L_ci[0] <= kTrueKL && kTrueKL <= s.k_L_ci[1];
    cover_R += s.k_R_ci[0] <= kTrueKR && kTrueKR <= s.k_R_ci[1];
    sum_L += s.k_L;
    sum_R += s.k_R;
    ++n;
  }
  double CoverL() const { return static_cast<double>(cover_L) / n; }
  double CoverR() const { return static_cast<double>(cover_R) / n; }
  double BiasL() const { return sum_L / n / kTrueKL - 1.0; }
  double BiasR() const { return sum_R / n / kTrueKR - 1.0; }
};

}  // namespace

TEST_CASE("fit-noise is unbiased with uncorrected systematic errors (400 campaigns)", "[fit_noise][systematic]") {
  const auto path = BackAndForthPath(10.0);
  NoiseFitInputOptions in;
  in.sigma_xy_m = 0.0005;
  in.sigma_theta_rad = Deg2Rad(0.1);
  WheelNoiseFitOptions reml;  // fit-noise's default
  reml.restricted = true;
  Tally ignored, estimated, given;
  std::mt19937_64 draw(2024);
  std::uniform_real_distribution<double> Ed(0.99, 1.01), Eb(0.97, 1.03);
  const int campaigns = 400;
  for (int c = 0; c < campaigns; ++c) {
    const double E_d = Ed(draw), E_b = Eb(draw);
    const EndpointData data = Simulate(path, E_d, E_b, 60, 5000 + static_cast<std::uint64_t>(c), "fwd_back");
    // As fit-noise did before: the covariance along the odometry's path.
    ignored.Add(FitWheelNoise(NoiseRunsFromEndpoints(data, path, kB, "", in), reml));
    // Estimated jointly (fit-noise's default).
    estimated.Add(FitWheelNoiseWithSystematics(
        [&](const SystematicErrors& e) {
          NoiseFitInputOptions with = in;
          with.systematic = e;
          return NoiseRunsFromEndpoints(data, path, kB, "", with);
        },
        reml, nullptr));
    // Given (fit-noise --params CAL.json): the true factors.
    NoiseFitInputOptions known = in;
    known.systematic = {E_b, 2.0 / (E_d + 1.0), 2.0 * E_d / (E_d + 1.0)};
    given.Add(FitWheelNoise(NoiseRunsFromEndpoints(data, path, kB, "", known), reml));
  }
  auto report = [](const char* name, const Tally& t) {
    return fmt::format("{}: coverage k_L {:.3f}, k_R {:.3f}; bias k_L {:+.4f}, k_R {:+.4f}", name, t.CoverL(),
                       t.CoverR(), t.BiasL(), t.BiasR());
  };
  WARN(report("systematic errors ignored", ignored));
  WARN(report("estimated jointly", estimated));
  WARN(report("given (--params)", given));
  // Ignoring them is what the joint estimate fixes: far outside.
  CHECK(ignored.BiasL() > 0.2);
  CHECK(ignored.CoverL() < 0.6);
  // Binomial tolerances. fit-noise's default (estimated jointly): a true
  // coverage of 0.95 over 400 campaigns has a standard deviation of
  // sqrt(0.95 * 0.05 / 400) = 0.0109; the check is 0.95 +- 3 of them,
  // [0.917, 0.983] (a correct method fails it with probability 0.3 %). The
  // previous delta-method widening (0.895 for k_L over 4000 campaigns)
  // fails it. --params (the true factors): the issue's band 93-97 % widened
  // by 3 binomial standard deviations at its ends, [0.892, 0.996] (these
  // 400 campaigns give 0.912 for k_L; 1000 give 0.93-0.95, see
  // docs/noise-model.md). Bias: under 3 % (the issue's); its standard error
  // over 400 campaigns is about 0.5 %.
  const double sd95 = std::sqrt(0.95 * 0.05 / campaigns);
  const double lo = 0.93 - 3.0 * std::sqrt(0.93 * 0.07 / campaigns), hi = 0.97 + 3.0 * std::sqrt(0.97 * 0.03 / campaigns);
  CHECK(std::abs(estimated.CoverL() - 0.95) <= 3.0 * sd95);
  CHECK(std::abs(estimated.CoverR() - 0.95) <= 3.0 * sd95);
  CHECK(given.CoverL() >= lo);
  CHECK(given.CoverL() <= hi);
  CHECK(given.CoverR() >= lo);
  CHECK(given.CoverR() <= hi);
  for (const Tally* t : {&estimated, &given}) {
    CHECK(std::abs(t->BiasL()) < 0.03);
    CHECK(std::abs(t->BiasR()) < 0.03);
  }
}

TEST_CASE("fit-noise's joint E_d: few likelihood passes, E_d recovered", "[fit_noise][systematic]") {
  // One campaign with E_d = 0.993: the joint fit finds E_d within 3 of its
  // standard errors, and the whole fit with both intervals takes far fewer
  // likelihood passes than the old Brent-in-bisection search (~2,500).
  const auto path = BackAndForthPath(10.0);
  NoiseFitInputOptions in;
  in.sigma_xy_m = 0.0005;
  in.sigma_theta_rad = Deg2Rad(0.1);
  const EndpointData data = Simulate(path, 0.993, 1.0, 120, 77, "fwd_back");
  SystematicEstimate e;
  const WheelNoiseFitSummary s = FitWheelNoiseWithSystematics(
      [&](const SystematicErrors& x) {
        NoiseFitInputOptions with = in;
        with.systematic = x;
        return NoiseRunsFromEndpoints(data, path, kB, "", with);
      },
      {}, &e);
  INFO(s.BriefReport() << "; E_d " << e.value.c_R / e.value.c_L << " +- " << e.E_d_se << "; passes "
                       << s.likelihood_passes);
  CHECK(e.E_d_se > 0.0);
  CHECK(std::abs(e.value.c_R / e.value.c_L - 0.993) < 3.0 * e.E_d_se);
  CHECK_FALSE(e.E_b_determined);  // no turn: the means do not show E_b
  CHECK(s.likelihood_passes < 250);
}

TEST_CASE("fit-noise CLI: k at the boundary is 'not determined'; --params and --systematic estimate", "[fit_noise][cli]") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / fmt::format("umbmark_fit_noise_sys_{}", ::getpid());
  fs::create_directories(dir);
  auto write = [](const fs::path& p, const std::string& text) {
    std::ofstream f(p);
    f << text;
  };
  write(dir / "robot.toml", "wheelbase_m = 0.371\nwheel_diameter_left_m = 0.1\nwheel_diameter_right_m = 0.1\n");
  // E_d = 0.995, E_b = 1.02 (an uncalibrated robot), 60 runs of 10 m forward and back.
  const EndpointData d = Simulate(BackAndForthPath(10.0), 0.995, 1.02, 60, 99, "fwd_back");
  std::string csv = "run,direction,ex_m,ey_m,etheta_rad\n";
  for (const auto& r : d.runs) csv += fmt::format("{},{},{:.17g},{:.17g},{:.17g}\n", r.run, r.direction, r.ex_m, r.ey_m, *r.etheta_rad);
  write(dir / "fb.csv", csv);
  // The calibration as `calibrate --json` writes it (true robot).
  const double cL = 2.0 / 1.995, cR = 2.0 * 0.995 / 1.995;
  write(dir / "cal.json", fmt::format(R"({{"parameters": {{"wheelbase_m": {}, "wheel_diameter_left_m": {}, "wheel_diameter_right_m": {}}}}})",
                                      0.371 * 1.02, 0.1 * cL, 0.1 * cR));
  const std::string base = fmt::format("fit-noise {} --robot {} --distance 10 --meas-sigma 0.0005,0.001745 --json -",
                                       (dir / "fb.csv").string(), (dir / "robot.toml").string());
  const auto plain = testing::RunCli(base + " --systematic none");
  const auto deflt = testing::RunCli(base);
  const auto given = testing::RunCli(base + " --params " + (dir / "cal.json").string());
  const auto est = testing::RunCli(base + " --systematic estimate");
  REQUIRE(plain.status == 0);
  REQUIRE(given.status == 0);
  REQUIRE(est.status == 0);
  REQUIRE(deflt.status == 0);
  CHECK(nlohmann::json::parse(deflt.out)["systematic_errors"]["source"] == "estimated");  // the default
  const auto jp = nlohmann::json::parse(plain.out), jg = nlohmann::json::parse(given.out),
             je = nlohmann::json::parse(est.out);
  CHECK(jg["systematic_errors"]["source"] == "params");
  CHECK(jg["systematic_errors"]["E_b"].get<double>() == Approx(1.02).epsilon(1e-12));
  CHECK(je["systematic_errors"]["source"] == "estimated");
  CHECK(jp["systematic_errors"]["source"] == "none");
  // The truth lies in the --params and the estimated intervals.
  for (const auto* j : {&jg, &je}) {
    CHECK((*j)["k_L_ci95"][0].get<double>() <= kTrueKL);
    CHECK((*j)["k_L_ci95"][1].get<double>() >= kTrueKL);
    CHECK((*j)["k_R_ci95"][0].get<double>() <= kTrueKR);
    CHECK((*j)["k_R_ci95"][1].get<double>() >= kTrueKR);
    CHECK((*j)["k_L_determined"] == true);
  }
  CHECK(testing::RunCli(base + " --systematic estimate --params " + (dir / "cal.json").string()).status == 2);

  // k_L = 0 (a noiseless left wheel): about half of such campaigns put the
  // maximum-likelihood k_L at the boundary 0; the first seed that does is
  // written and read back through the command.
  {
    sim::SimulationModel m;
    m.nominal.wheelbase_m = kB;
    m.nominal.wheel_diameter_left_m = m.nominal.wheel_diameter_right_m = 0.1;
    m.noise = {0.0, kTrueKR};
    const auto spec = BackAndForthPath(10.0);
    const sim::SimPlan plan = sim::CompilePlan(m, ToWheelSegments(spec, kB), 100);
    std::string z;
    for (std::uint64_t seed = 1; seed <= 20 && z.empty(); ++seed) {
      std::vector<Pose2> truth(60);
      sim::SimulateFinalPoses(plan, seed, 0, 60, truth.data());
      EndpointData e;
      for (std::size_t i = 0; i < truth.size(); ++i) {
        ReturnError r;
        r.run = std::to_string(i + 1);
        r.direction = "fwd_back";
        r.ex_m = truth[i].x - plan.odometry_final.x;
        r.ey_m = truth[i].y - plan.odometry_final.y;
        r.etheta_rad = WrapAngle(truth[i].theta - plan.odometry_final.theta);
        e.runs.push_back(r);
      }
      const auto s = FitWheelNoise(NoiseRunsFromEndpoints(e, spec, kB, "", NoiseFitInputOptions{}));
      if (s.k_L > 1e-3 * s.k_L_ci[1]) continue;
      z = "run,direction,ex_m,ey_m,etheta_rad\n";
      for (const auto& r : e.runs) z += fmt::format("{},fwd_back,{:.17g},{:.17g},{:.17g}\n", r.run, r.ex_m, r.ey_m, *r.etheta_rad);
    }
    REQUIRE(!z.empty());
    write(dir / "zero.csv", z);
    const auto r = testing::RunCli(fmt::format("fit-noise {} --robot {} --distance 10 --systematic none --ml --json -", (dir / "zero.csv").string(),
                                               (dir / "robot.toml").string()));
    REQUIRE(r.status == 0);
    const auto j = nlohmann::json::parse(r.out);
    CHECK(j["k_L"].is_number());  // contract: numeric
    CHECK(j["k_L_determined"] == false);
    CHECK(j["k_L_upper95"].get<double>() > 0.0);
    CHECK(j["k_L_upper95"].get<double>() < kTrueKR);
    CHECK(j["k_R_determined"] == true);
    // Back-and-forth runs move both wheels alike: the warning names the bound
    // and the runs that would separate k_L from k_R.
    const double upper = j["k_L_upper95"].get<double>();
    const std::string bound = fmt::format("only bounded: k_L < {:.3g} m^1/2 at 95 %", upper);
    REQUIRE(j["warnings"].size() == 1);
    const std::string warning = j["warnings"][0].get<std::string>();
    CHECK(warning.find("k_L is not determined by these runs") != std::string::npos);
    CHECK(warning.find(bound) != std::string::npos);
    CHECK(warning.find("arcs or circles in both directions, pivot turns on each wheel") != std::string::npos);
    const auto html = dir / "zero.html";
    const auto text = testing::RunCli(fmt::format("fit-noise {} --robot {} --distance 10 --systematic none --ml --report {}",
                                                  (dir / "zero.csv").string(), (dir / "robot.toml").string(), html.string()));
    REQUIRE(text.status == 0);
    CHECK(text.out.find(fmt::format("k_L not determined (at the boundary 0); 95% upper bound {:.4g} m^1/2", upper)) !=
          std::string::npos);
    CHECK(text.out.find("WARNING: " + warning) != std::string::npos);
    std::ifstream in(html);
    const std::string page((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    // The headline gives k_R's interval and, for k_L, the bound only (never "0 to ...").
    CHECK(page.find(fmt::format("k_L not determined (only bounded: k_L &lt; {:.3g} m^1/2 at 95 %)", upper)) != std::string::npos);
    CHECK(page.find(fmt::format("k_R = {:.3g} m^1/2 (95%: {:.3g} to {:.3g})", j["k_R"].get<double>(),
                                j["k_R_ci95"][0].get<double>(), j["k_R_ci95"][1].get<double>())) != std::string::npos);
    const auto head = page.find("<section class=\"headline");
    REQUIRE(head != std::string::npos);
    const std::string headline = page.substr(head, page.find("</section>", head) - head);
    CHECK(headline.find("k_L = ") == std::string::npos);
    CHECK(headline.find("k_L not determined") != std::string::npos);
    CHECK(page.find("To determine k_L: runs in which the two wheels travel different distances") != std::string::npos);
  }
  fs::remove_all(dir);
}

TEST_CASE("fit-noise CLI: E_d is kept at the means' value, with a warning, when the scatter does not fit", "[fit_noise][cli]") {
  // 3000 trajectory runs of 1 m forward and back (a path that retraces
  // itself: the means do not show E_d, so its prior stays weak) whose
  // lateral error is NOT the wheel-noise model's (y = theta / 2 plus
  // independent 0.3 mm): the joint fit would pull E_d far from 1 to bend the
  // model onto the misfit. (On straight runs the means pin E_d.)
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / fmt::format("umbmark_fit_noise_ed_{}", ::getpid());
  fs::create_directories(dir);
  {
    std::ofstream f(dir / "robot.toml");
    f << "wheelbase_m = 0.371\nwheel_diameter_left_m = 0.1\nwheel_diameter_right_m = 0.1\n";
  }
  std::mt19937_64 rng(7);
  std::normal_distribution<double> N01;
  std::string csv = "run,direction,t_s,dist_left_m,dist_right_m,x_gt_m,y_gt_m,theta_gt_rad\n";
  for (int i = 1; i <= 3000; ++i) {
    const char* d = i % 2 ? "cw" : "ccw";
    const double L = 0.0014 * N01(rng), R = 0.0014 * N01(rng), th = (R - L) / kB;
    csv += fmt::format("{},{},0,0,0,0,0,0\n{},{},1,1.0,1.0,1,0,0\n{},{},2,0.0,0.0,{:.9f},{:.9f},{:.9f}\n", i, d, i, d,
                       i, d, 0.5 * (L + R), 0.5 * th + 0.0003 * N01(rng), th);
  }
  {
    std::ofstream f(dir / "straight.csv");
    f << csv;
  }
  const auto r = testing::RunCli(fmt::format("fit-noise {} --robot {} --meas-sigma 0.0005,0.001 --json -",
                                             (dir / "straight.csv").string(), (dir / "robot.toml").string()));
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j["systematic_errors"]["source"] == "estimated");
  CHECK(j["systematic_errors"]["E_d_determined"] == false);
  CHECK(std::abs(j["systematic_errors"]["E_d"].get<double>() - 1.0) < 0.01);
  REQUIRE(!j["warnings"].empty());
  CHECK(j["warnings"][0].get<std::string>().find("the scatter pulled E_d more than 0.05") != std::string::npos);
  fs::remove_all(dir);
}
