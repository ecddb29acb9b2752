// castor_swivel's random parts (an extension beyond the contract; docs/
// diagnosis.md "A swivel castor's random parts"): the run's first start
// kicks the heading by N(0, kappa_start^2) and slips the position by
// N(0, slip_start^2) per robot axis, the kick after a spot turn scatters by
// N(0, kappa_sd^2) around kappa. The simulator against its definition on
// noise-free runs (sample moments over many runs, with their sampling
// tolerance), the range checks, and the diagnosis recovering kappa and the
// three sds on a campaign with wheel noise (a Monte Carlo tolerance from
// bench/castor_first_start_mc.sh). The defaults (all 0) are the contract's
// castor_swivel exactly: test_effects_slide_swivel and test_model_bitwise
// are unchanged.
#include <catch2/catch.hpp>

#include <cmath>
#include <numeric>
#include <variant>
#include <vector>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "diagnosis/diagnose.hpp"
#include "simulation/campaign_sim.hpp"
#include "simulation/effects.hpp"
#include "support/diag_campaign.hpp"
#include "support/effect_campaign.hpp"

using namespace umbmark;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

constexpr double kSide = 2.0;  // square side [m]

double Sd(const std::vector<double>& v) {
  const double m = std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

double Mean(const std::vector<double>& v) {
  return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

}  // namespace

TEST_CASE(
    "castor_swivel: the first start kicks N(0 kappa_start^2) and slips N(0 slip_start^2) and the turns kicks scatter "
    "by kappa_sd",
    "[effects][issue28]") {
  const double kappa = 0.01, kappa_start = 0.02, slip = 0.003, kappa_sd = 0.004;
  sim::CampaignSimOptions o = testing::QuietOptions(150, 1);
  o.effects.swivel_kappa = kappa;
  o.effects.swivel_kappa_start = kappa_start;
  o.effects.swivel_slip_start = slip;
  const sim::SimulatedCampaign c = sim::SimulateCampaign(testing::QuietManifest(0.4, kSide, kSide), o);
  const auto& runs = std::get<TrajectoryData>(c.data[0]).runs;
  REQUIRE(runs.size() == 300);
  std::vector<double> kick, along, left;
  for (const auto& run : runs) {
    // The three kicks after the turns are exactly kappa x the turn's sign:
    // the rest of the final heading is the first start's kick.
    const double sign = run.direction == "cw" ? -1.0 : 1.0;
    const double d = run.GroundTruth(run.size() - 1).theta - sign * (2.0 * kPi + 3.0 * kappa);
    kick.push_back(d);
    // Before the first turn the robot stands at the first leg's end: the
    // slip, rotated back into the robot's frame at the start, is what is
    // left of that pose after the leg (kSide along the kicked heading).
    std::size_t i = 0;
    while (i + 1 < run.size() && run.t_s[i + 1] <= o.pause_s + kSide / o.speed_m_s + 0.5 * o.pause_s) ++i;
    const Pose2 end = run.GroundTruth(i);
    REQUIRE_THAT(end.theta, WithinAbs(d, 1e-12));
    const double X = end.x - kSide * std::cos(d), Y = end.y - kSide * std::sin(d);
    along.push_back(std::cos(d) * X + std::sin(d) * Y);
    left.push_back(-std::sin(d) * X + std::cos(d) * Y);
  }
  // 300 draws: an sd within 4 standard errors (1/sqrt(2 n) = 4.1 %) is
  // 16.3 %, a mean within 4 sd / sqrt(n).
  const double n = static_cast<double>(kick.size()), rel = 4.0 / std::sqrt(2.0 * n);
  CHECK_THAT(Sd(kick), WithinRel(kappa_start, rel));
  CHECK_THAT(Mean(kick), WithinAbs(0.0, 4.0 * kappa_start / std::sqrt(n)));
  CHECK_THAT(Sd(along), WithinRel(slip, rel));
  CHECK_THAT(Sd(left), WithinRel(slip, rel));
  CHECK_THAT(Mean(along), WithinAbs(0.0, 4.0 * slip / std::sqrt(n)));

  // kappa_sd: each square's three kicks after turns scatter around kappa
  // (kappa_start off: the final heading holds their sum alone).
  sim::CampaignSimOptions t = testing::QuietOptions(100, 1);
  t.effects.swivel_kappa = kappa;
  t.effects.swivel_kappa_sd = kappa_sd;
  const sim::SimulatedCampaign ct = sim::SimulateCampaign(testing::QuietManifest(0.4, kSide, kSide), t);
  std::vector<double> sum3;
  for (const auto& run : std::get<TrajectoryData>(ct.data[0]).runs) {
    const double sign = run.direction == "cw" ? -1.0 : 1.0;
    sum3.push_back(run.GroundTruth(run.size() - 1).theta - sign * (2.0 * kPi + 3.0 * kappa));
  }
  const double m3 = static_cast<double>(sum3.size());
  CHECK_THAT(Sd(sum3), WithinRel(std::sqrt(3.0) * kappa_sd, 4.0 / std::sqrt(2.0 * m3)));
  CHECK_THAT(Mean(sum3), WithinAbs(0.0, 4.0 * std::sqrt(3.0) * kappa_sd / std::sqrt(m3)));
}

TEST_CASE("castor_swivel: its random parts' ranges are checked", "[effects][issue28]") {
  CHECK(testing::EffectSpecError("castor_swivel:kappa=0.01,kappa_start=-0.01").find("castor_swivel.kappa_start = -0.01 must be in "
                                                                        "[0, 0.5] rad") != std::string::npos);
  CHECK(testing::EffectSpecError("castor_swivel:kappa=0.01,slip_start=0.2").find("castor_swivel.slip_start = 0.2 must be in [0, "
                                                                     "0.1] m") != std::string::npos);
  CHECK(testing::EffectSpecError("castor_swivel:kappa=0.01,kappa_sd=nan").find("must be in") != std::string::npos);
  CHECK(testing::EffectSpecError("castor_swivel:kappa=0.01,kappa_start=0.03,slip_start=0.002,kappa_sd=0.003").empty());
}

TEST_CASE("diagnose: castor_swivel's kappa and its random parts are recovered with wheel noise", "[diagnose][issue28]") {
  // The squares' first legs and turns, the back-and-forth runs' first
  // starts: 20 + 20 runs, 60 starts after a turn. Tolerances: about 3x
  // the Monte Carlo sd over 20 seeds of bench/castor_first_start_mc.sh
  // (14 %, 8 %, 28 %; docs/diagnosis.md), 35 % at least.
  testing::SmallCampaign s = testing::MakeSmallCampaign(2801, 10, 20);
  s.sim.effects.swivel_kappa = 0.006;
  s.sim.effects.swivel_kappa_start = 0.02;
  s.sim.effects.swivel_slip_start = 0.003;
  s.sim.effects.swivel_kappa_sd = 0.003;
  diag::DiagnoseOptions o;
  o.null_simulations = 100;
  o.seed = 1;
  o.threads = 2;
  o.pieces.folds = 4;
  const diag::DiagnoseSummary d = diag::Diagnose(testing::BuildSmallCampaign(s), o);
  CHECK(d.verdict == "castor_swivel");
  const diag::Candidate* c = nullptr;
  for (const auto& cd : d.candidates)
    if (cd.effect == sim::EffectKind::kCastorSwivel) c = &cd;
  REQUIRE(c);
  CHECK_THAT(c->params.at("kappa"), WithinAbs(0.006, 5.0 * c->param_se.at("kappa")));
  CHECK_THAT(c->params.at("kappa_start"), WithinRel(0.02, 0.45));
  CHECK_THAT(c->params.at("slip_start"), WithinRel(0.003, 0.35));
  CHECK_THAT(c->params.at("kappa_sd"), WithinRel(0.003, 0.85));
}
