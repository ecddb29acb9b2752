// `diagnose --baseline CAL.json [--kl K --kr K]` (lib/diagnosis/baseline_given.hpp):
// campaigns simulated with a known true robot are compared with a given
// model that has one parameter wrong by a known amount; the diagnosis must
// name that parameter and recover the size of the error (the tolerances
// below are about 4 standard errors of each estimate on these campaigns:
// wheelbase se 0.14 mm, diameter ratio se 210 ppm, noise ratio se ~6 %),
// say `none` for a correct model, and refuse bad input with a message
// naming the file or flag.
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "diagnosis/baseline_given.hpp"
#include "diagnosis/diagnose.hpp"
#include "diagnosis/pieces.hpp"
#include "formats/campaign_writer.hpp"
#include "simulation/campaign_sim.hpp"
#include "support/diag_campaign.hpp"
#include "support/run_cli.hpp"

using namespace umbmark;
using namespace umbmark::diag;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

RobotParams Recorded() {
  RobotParams r;
  r.wheelbase_m = 0.35;
  r.wheel_diameter_left_m = 0.1;
  r.wheel_diameter_right_m = 0.1;
  r.ticks_per_rev = 8192;
  return r;
}

constexpr double kTrueEd = 1.004, kTrueEb = 1.012, kTrueKL = 1.5e-3, kTrueKR = 2.5e-3;

/// Squares (cw, ccw) and back-and-forth runs plus three free paths (arcs),
/// 10 Hz, 0.5 m/s, the true robot above.
sim::SimulatedCampaign Simulate(std::uint64_t seed) {
  Manifest m = sim::StandardCampaignManifest(Recorded(), 2.0, 2.0, GroundTruthNoise{3e-4, 1.5e-3});
  testing::AddFreeExperiment(m, "free.csv");
  sim::CampaignSimOptions o;
  o.seed = seed;
  o.truth.E_d = kTrueEd;
  o.truth.E_b = kTrueEb;
  o.truth.k_L = kTrueKL;
  o.truth.k_R = kTrueKR;
  o.square_runs_per_direction = 5;
  o.back_and_forth_runs = 10;
  o.free_runs = 3;
  o.sample_rate_hz = 10.0;
  o.speed_m_s = 0.5;
  o.pause_s = 0.5;
  return sim::SimulateCampaign(m, o);
}

/// The true robot's parameters, as a correct `calibrate` would give them.
RobotParams TrueCal() {
  RobotParams r = Recorded();
  r.wheelbase_m *= kTrueEb;
  r.wheel_diameter_left_m *= 2.0 / (kTrueEd + 1.0);
  r.wheel_diameter_right_m *= 2.0 * kTrueEd / (kTrueEd + 1.0);
  return r;
}

GivenModel Given(const RobotParams& p, double kL = kTrueKL, double kR = kTrueKR) {
  GivenModel g;
  g.params = p;
  g.source = "CAL.json";
  g.noise_given = true;
  g.k_L = kL;
  g.k_R = kR;
  return g;
}

DiagnoseOptions Fast(const GivenModel& g) {
  DiagnoseOptions o;
  o.null_simulations = 100;
  o.seed = 1;
  o.threads = 2;
  o.pieces.folds = 4;
  o.given = g;
  return o;
}

const ExplanationStep* Step(const DiagnoseSummary& s, sim::EffectKind k) {
  for (const auto& e : s.explanation)
    if (e.effect == k) return &e;
  return nullptr;
}

std::string Describe(const DiagnoseSummary& d) {
  std::string out = fmt::format("verdict {} ({})\n", d.verdict, d.verdict_reason);
  for (const auto& e : d.explanation) {
    out += fmt::format("  step {} heldout {:.3f} rel {:.3f}:", sim::EffectToString(e.effect),
                       e.cumulative_heldout_shrink, e.relative_size);
    for (const auto& [k, v] : e.params) out += fmt::format(" {}={:.6g}", k, v);
    out += "\n";
  }
  for (const auto& c : d.candidates) {
    out += fmt::format("  candidate {} evidence {:.1f}:", sim::EffectToString(c.effect), c.evidence);
    for (const auto& [k, v] : c.param_se) out += fmt::format(" se({})={:.3g}", k, v);
    out += "\n";
  }
  return out;
}

}  // namespace

TEST_CASE("baseline model: the given parameters map onto E_d, E_b and scale", "[diagnose][baseline]") {
  const ParamVector p = GivenParams(Recorded(), TrueCal());
  CHECK_THAT(p[kParamEd], WithinRel(kTrueEd, 1e-12));
  CHECK_THAT(p[kParamEb], WithinRel(kTrueEb, 1e-12));
  CHECK_THAT(p[kParamScale], WithinAbs(0.0, 1e-12));
  RobotParams big = TrueCal();
  big.wheel_diameter_left_m *= 1.01;
  big.wheel_diameter_right_m *= 1.01;
  const ParamVector q = GivenParams(Recorded(), big);
  CHECK_THAT(q[kParamEd], WithinRel(kTrueEd, 1e-12));
  CHECK_THAT(q[kParamScale], WithinAbs(0.01, 1e-12));
}

TEST_CASE("diagnose --baseline: a correct model gives none", "[diagnose][baseline]") {
  const sim::SimulatedCampaign sc = Simulate(301);
  const CampaignData c = BuildCampaign(sc.manifest, sc.data);
  const DiagnoseSummary d = Diagnose(c, Fast(Given(TrueCal())));
  INFO(Describe(d));
  CHECK(d.verdict == "none");
  CHECK(d.corrections.empty());
  REQUIRE(d.baseline.given.has_value());
  CHECK_THAT(d.baseline.E_b, WithinRel(kTrueEb, 1e-12));
  CHECK_THAT(d.baseline.k_L, WithinRel(kTrueKL, 1e-9));
}

TEST_CASE("diagnose --baseline: a wheelbase 4 mm too long is named and recovered", "[diagnose][baseline]") {
  const sim::SimulatedCampaign sc = Simulate(302);
  const CampaignData c = BuildCampaign(sc.manifest, sc.data);
  RobotParams cal = TrueCal();
  cal.wheelbase_m += 0.004;
  const DiagnoseSummary d = Diagnose(c, Fast(Given(cal)));
  INFO(Describe(d));
  CHECK(d.verdict == "wheelbase_error");
  const ExplanationStep* s = Step(d, sim::EffectKind::kWheelbaseError);
  REQUIRE(s);
  CHECK_THAT(s->params.at("error_mm"), WithinAbs(4.0, 0.6));
  CHECK_THAT(s->params.at("wheelbase_m"), WithinAbs(TrueCal().wheelbase_m, 6e-4));
  REQUIRE_FALSE(d.corrections.empty());
  CHECK(d.corrections.front().parameter == "wheelbase_m");
  CHECK_THAT(d.corrections.front().corrected, WithinAbs(TrueCal().wheelbase_m, 6e-4));
}

TEST_CASE("diagnose --baseline: a diameter ratio 0.3 % off is named and recovered", "[diagnose][baseline]") {
  const sim::SimulatedCampaign sc = Simulate(303);
  const CampaignData c = BuildCampaign(sc.manifest, sc.data);
  RobotParams cal = TrueCal();
  // D_R / D_L 3000 ppm too large, mean diameter kept.
  cal.wheel_diameter_left_m *= 1.0 - 1.5e-3;
  cal.wheel_diameter_right_m *= 1.0 + 1.5e-3;
  const double given_ppm = 1e6 * ((1.0 + 1.5e-3) / (1.0 - 1.5e-3) - 1.0);
  const DiagnoseSummary d = Diagnose(c, Fast(Given(cal)));
  INFO(Describe(d));
  CHECK(d.verdict == "diameter_ratio_error");
  const ExplanationStep* s = Step(d, sim::EffectKind::kDiameterRatioError);
  REQUIRE(s);
  CHECK_THAT(s->params.at("error_ppm"), WithinAbs(given_ppm, 800.0));
  CHECK_THAT(s->params.at("wheel_diameter_left_m"), WithinRel(TrueCal().wheel_diameter_left_m, 5e-4));
  CHECK_THAT(s->params.at("wheel_diameter_right_m"), WithinRel(TrueCal().wheel_diameter_right_m, 5e-4));
}

TEST_CASE("diagnose --baseline: wheel noise given x2 and x0.5 is named, the ratio recovered", "[diagnose][baseline]") {
  const sim::SimulatedCampaign sc = Simulate(304);
  const CampaignData c = BuildCampaign(sc.manifest, sc.data);
  for (const double factor : {2.0, 0.5}) {
    const DiagnoseSummary d = Diagnose(c, Fast(Given(TrueCal(), factor * kTrueKL, factor * kTrueKR)));
    INFO(factor << "\n" << Describe(d));
    CHECK(d.verdict == "wheel_noise_error");
    const ExplanationStep* s = Step(d, sim::EffectKind::kWheelNoiseError);
    REQUIRE(s);
    CHECK_FALSE(s->negligible);
    CHECK_THAT(s->params.at("ratio_L"), WithinRel(1.0 / factor, 0.25));
    CHECK_THAT(s->params.at("ratio_R"), WithinRel(1.0 / factor, 0.25));
    // Both wheels off: both k get a correction, one text for both.
    REQUIRE(d.corrections.size() == 2);
    CHECK(d.corrections[0].parameter == "k_L");
    CHECK(d.corrections[1].parameter == "k_R");
    CHECK_THAT(d.corrections[0].corrected, WithinRel(kTrueKL, 0.25));
    CHECK_THAT(d.corrections[1].corrected, WithinRel(kTrueKR, 0.25));
    CHECK(d.corrections[0].text.find("(left) and off by x") != std::string::npos);
    // The evidence is the likelihood, not the mean gap it does not change.
    const std::string text = DiagnoseReport(d);
    CHECK(text.find("evidence for wheel_noise_error: very strong evidence: runs not used to fit it are") !=
          std::string::npos);
    CHECK(text.find("not where they lie on average") != std::string::npos);
  }
}

TEST_CASE("diagnose --baseline: one wheel's noise wrong is named on that wheel", "[diagnose][baseline]") {
  // Only k_L (or only k_R) off, x0.5 or x2: wheel_noise_error with that
  // wheel's ratio k_fit / k_given near 1/factor and the other near 1, not
  // bump_outliers (whose Gaussian limit, many small bumps, is the same
  // extra wheel noise).
  const sim::SimulatedCampaign sc = Simulate(305);
  const CampaignData c = BuildCampaign(sc.manifest, sc.data);
  for (const bool left : {true, false}) {
    for (const double factor : {0.5, 2.0}) {
      const DiagnoseSummary d = Diagnose(
          c, Fast(Given(TrueCal(), left ? factor * kTrueKL : kTrueKL, left ? kTrueKR : factor * kTrueKR)));
      INFO((left ? "k_L x" : "k_R x") << factor << "\n" << Describe(d));
      CHECK(d.verdict == "wheel_noise_error");
      const ExplanationStep* s = Step(d, sim::EffectKind::kWheelNoiseError);
      REQUIRE(s);
      CHECK_THAT(s->params.at(left ? "ratio_L" : "ratio_R"), WithinRel(1.0 / factor, 0.25));
      CHECK_THAT(s->params.at(left ? "ratio_R" : "ratio_L"), WithinAbs(1.0, 0.15));
      // The correction names only the wrong wheel's k and keeps the other.
      REQUIRE(d.corrections.size() == 1);
      const ParameterCorrection& pc = d.corrections.front();
      CHECK(pc.parameter == (left ? "k_L" : "k_R"));
      CHECK(pc.given == Approx(factor * (left ? kTrueKL : kTrueKR)));
      CHECK_THAT(pc.corrected, WithinRel(left ? kTrueKL : kTrueKR, 0.25));
      const std::string keep = left ? "k_R" : "k_L";
      CHECK(pc.text.find(fmt::format("the simulation's {} wheel noise is off by x", left ? "left" : "right")) !=
            std::string::npos);
      CHECK(pc.text.find(fmt::format("{} = {:.3g} m^1/2 is consistent with the runs", keep,
                                     left ? kTrueKR : kTrueKL)) != std::string::npos);
      CHECK(pc.text.find("set " + keep) == std::string::npos);
      CHECK(DiagnoseReport(d).find("    " + pc.text + "\n") != std::string::npos);
    }
  }
}

TEST_CASE("umbmark diagnose --baseline: JSON keys, corrections, bad input", "[diagnose][baseline][cli]") {
  using testing::Q;
  const auto dir = testing::TempDir("diagnose-baseline");
  const sim::SimulatedCampaign sc = Simulate(305);
  const std::string manifest = io::WriteCampaign(sc.manifest, sc.data, (dir / "campaign").string());
  RobotParams cal = TrueCal();
  cal.wheelbase_m -= 0.004;
  const std::string cal_path = (dir / "cal.json").string();
  {
    std::ofstream f(cal_path);
    f << nlohmann::json{{"parameters",
                         {{"wheelbase_m", cal.wheelbase_m},
                          {"wheel_diameter_left_m", cal.wheel_diameter_left_m},
                          {"wheel_diameter_right_m", cal.wheel_diameter_right_m}}}}
             .dump(2);
  }
  const std::string base = "diagnose " + Q(manifest) + " --null-sims 50 --folds 3 --baseline " + Q(cal_path);
  auto r = testing::RunCli(base + fmt::format(" --kl {} --kr {} --json {}", kTrueKL, kTrueKR, Q(dir / "d.json")));
  INFO(r.out << r.err);
  REQUIRE(r.status == 0);
  CHECK(r.out.find("wheelbase_m") != std::string::npos);
  // The next steps say what to change, and never ask to simulate a parameter error as an effect.
  CHECK(r.out.find("Change your simulation: the simulation's wheelbase is") != std::string::npos);
  CHECK(r.out.find("--effect wheelbase_error") == std::string::npos);
  const auto j = nlohmann::json::parse(testing::Slurp((dir / "d.json").string()));
  CHECK(j["verdict"]["effect"] == "wheelbase_error");
  REQUIRE(j["baseline"]["given"].is_object());
  CHECK(j["baseline"]["given"]["source"] == cal_path);
  CHECK(j["baseline"]["given"]["noise_given"] == true);
  CHECK_THAT(j["baseline"]["given"]["wheelbase_m"].get<double>(), WithinRel(cal.wheelbase_m, 1e-12));
  REQUIRE(j["corrections"].is_array());
  REQUIRE(j["corrections"].size() == 1);
  CHECK(j["corrections"][0]["effect"] == "wheelbase_error");
  CHECK(j["corrections"][0]["parameter"] == "wheelbase_m");
  CHECK_THAT(j["corrections"][0]["corrected"].get<double>(), WithinAbs(TrueCal().wheelbase_m, 6e-4));
  CHECK(j["corrections"][0]["text"].get<std::string>().find("too short") != std::string::npos);
  int parameter_errors = 0;
  for (const auto& cd : j["candidates"]) {
    const std::string e = cd["effect"];
    if (e == "wheelbase_error" || e == "diameter_ratio_error" || e == "wheel_noise_error") ++parameter_errors;
    if (e == "wheelbase_error")
      for (const char* k : {"wheelbase_m", "wheelbase_given_m", "error_mm", "relative_error"})
        CHECK(cd["params"].contains(k));
  }
  CHECK(parameter_errors == 3);

  // Without --kl/--kr the noise is fitted and wheel_noise_error is no candidate.
  r = testing::RunCli(base + " --json -");
  REQUIRE(r.status == 0);
  const auto fitted = nlohmann::json::parse(r.out);
  CHECK(fitted["baseline"]["given"]["noise_given"] == false);
  for (const auto& cd : fitted["candidates"]) CHECK(cd["effect"] != "wheel_noise_error");

  // Bad input: the message names the file or flag.
  auto missing = testing::RunCli("diagnose " + Q(manifest) + " --baseline " + Q(dir / "nope.json"));
  CHECK(missing.status == 1);
  CHECK(missing.err.find("nope.json") != std::string::npos);
  const std::string bad_path = (dir / "bad.json").string();
  std::ofstream(bad_path) << "{\"parameters\": {\"wheelbase_m\": 0.35,";
  auto bad = testing::RunCli("diagnose " + Q(manifest) + " --baseline " + Q(bad_path));
  CHECK(bad.status == 1);
  CHECK(bad.err.find("bad.json") != std::string::npos);
  const std::string neg_path = (dir / "negative.json").string();
  std::ofstream(neg_path) << R"({"parameters": {"wheelbase_m": -0.35, "wheel_diameter_left_m": 0.1, "wheel_diameter_right_m": 0.1}})";
  auto neg = testing::RunCli("diagnose " + Q(manifest) + " --baseline " + Q(neg_path));
  CHECK(neg.status == 1);
  CHECK(neg.err.find("negative.json") != std::string::npos);
  auto half = testing::RunCli(base + " --kl 0.001");
  CHECK(half.status == 2);
  CHECK(half.err.find("--kr") != std::string::npos);
  auto negative_k = testing::RunCli(base + " --kl -0.001 --kr 0.001");
  CHECK(negative_k.status == 2);
  CHECK(negative_k.err.find("--kl") != std::string::npos);
  auto no_baseline = testing::RunCli("diagnose " + Q(manifest) + " --kl 0.001 --kr 0.001");
  CHECK(no_baseline.status == 2);
  CHECK(no_baseline.err.find("--baseline") != std::string::npos);
  auto effect_without = testing::RunCli("diagnose " + Q(manifest) + " --effects wheelbase_error");
  CHECK(effect_without.status == 2);
  CHECK(effect_without.err.find("--baseline") != std::string::npos);
  // The simulator refuses a parameter error as an effect.
  sim::Effects effects;
  CHECK_THROWS_WITH(sim::ParseEffectSpec("wheelbase_error:s=0.01", effects),
                    Catch::Contains("parameter error"));
}

TEST_CASE("diagnose --baseline: a wheel simulated without noise gets a correction without a ratio", "[diagnose][baseline]") {
  // k_L = 0 in the simulation: no ratio k_fit / k_given exists, so the text
  // says the simulation has none while the runs show some.
  const sim::SimulatedCampaign sc = Simulate(305);
  const CampaignData c = BuildCampaign(sc.manifest, sc.data);
  const DiagnoseSummary d = Diagnose(c, Fast(Given(TrueCal(), 0.0, kTrueKR)));
  INFO(Describe(d));
  CHECK(d.verdict == "wheel_noise_error");
  REQUIRE(d.corrections.size() == 1);
  CHECK(d.corrections[0].parameter == "k_L");
  CHECK(d.corrections[0].given == 0.0);
  CHECK_THAT(d.corrections[0].corrected, WithinRel(kTrueKL, 0.25));
  CHECK(d.corrections[0].text.find("left wheel noise is 0, but the runs show noise") != std::string::npos);
  CHECK(d.corrections[0].text.find("x0.00") == std::string::npos);
}
