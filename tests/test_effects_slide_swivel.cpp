// Issue 21's physics effects, stop_slide and castor_swivel (contract,
// "Effects"): the simulator against closed forms on noise-free runs, the
// range checks of their parameters (library and command line), the
// diagnosis' model replaying them exactly, the diagnosis naming them with
// their parameters recovered, and a clock offset told from a slide by the
// moving samples.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <variant>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "diagnosis/diagnose.hpp"
#include "diagnosis/model.hpp"
#include "diagnosis/pieces.hpp"
#include "simulation/campaign_sim.hpp"
#include "simulation/effects.hpp"
#include "support/diag_campaign.hpp"
#include "support/effect_campaign.hpp"
#include "support/run_cli.hpp"

using namespace umbmark;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

constexpr double kB = 0.4;     // nominal wheelbase [m]
constexpr double kSide = 2.0;  // square side [m]
constexpr double kDist = 2.0;  // back-and-forth distance [m]

const TrajectoryData& Traj(const sim::SimulatedCampaign& c, std::size_t e) {
  return std::get<TrajectoryData>(c.data[e]);
}

Pose2 Last(const TrajectoryRun& r) { return r.GroundTruth(r.size() - 1); }

/// Ground truth at the last sample at or before time t.
Pose2 AtOrBefore(const TrajectoryRun& r, double t) {
  std::size_t best = 0;
  for (std::size_t i = 0; i < r.size(); ++i)
    if (r.t_s[i] <= t + 1e-9) best = i;
  return r.GroundTruth(best);
}

const diag::Candidate* Find(const diag::DiagnoseSummary& s, sim::EffectKind k) {
  for (const auto& c : s.candidates)
    if (c.effect == k) return &c;
  return nullptr;
}

/// The diagnosis' parameters of the simulated truth (E_d, E_b and the
/// mean effects the simulator was given).
diag::ParamVector TrueParams(const testing::SmallCampaign& s) {
  const sim::Effects& fx = s.sim.effects;
  diag::ParamVector p = diag::NominalParams();
  p[diag::kParamEd] = s.sim.truth.E_d;
  p[diag::kParamEb] = s.sim.truth.E_b;
  p[diag::kParamScale] = fx.scale_s;
  p[diag::kParamKappa] = fx.castor_kappa;
  p[diag::kParamTau] = fx.time_tau;
  p[diag::kParamSlideD] = fx.slide_d;
  p[diag::kParamSlideA] = fx.slide_a;
  p[diag::kParamSlideArc] = fx.slide_arc;
  p[diag::kParamSlideBack] = fx.slide_back;
  p[diag::kParamSwivel] = fx.swivel_kappa;
  return p;
}

/// Largest |residual| of the noise-free campaign `c` under `p` (every
/// component, or only headings).
double Worst(const diag::MeanModel& model, const diag::ParamVector& p, bool heading_only = false) {
  std::vector<double> eps;
  model.Residuals(p, eps);
  double worst = 0.0;
  for (std::size_t j = heading_only ? 2 : 0; j < eps.size(); j += heading_only ? 3 : 1)
    worst = std::max(worst, std::abs(eps[j]));
  return worst;
}

diag::DiagnoseOptions Fast() {
  diag::DiagnoseOptions o;
  o.null_simulations = 100;
  o.seed = 1;
  o.threads = 2;
  o.pieces.folds = 4;
  return o;
}

}  // namespace

TEST_CASE("stop_slide: the chassis coasts d v^2 after a leg and a w^2 after a spot turn, only at stops",
          "[effects][issue21]") {
  const double d = 0.05, a = 0.02;
  sim::CampaignSimOptions o = testing::QuietOptions(2, 2);
  o.effects.slide_d = d;
  o.effects.slide_a = a;
  const sim::SimulatedCampaign c = sim::SimulateCampaign(testing::QuietManifest(kB, kSide, kDist), o);
  const double v = o.speed_m_s, w = o.turn_rate_rad_s;
  for (const auto& run : Traj(c, 1).runs) {
    // While the robot drives out, nothing slides (unlike a clock offset).
    for (std::size_t i = 0; i < run.size(); ++i) {
      const double t = run.t_s[i] - o.pause_s;
      if (t > 0.0 && t < kDist / v) CHECK_THAT(run.gt_x_m[i], WithinAbs(v * t, 1e-9));
    }
    // In the far pause: d v^2 beyond the leg's end.
    const Pose2 far = AtOrBefore(run, o.pause_s + kDist / v + 0.5 * o.pause_s);
    CHECK_THAT(far.x, WithinAbs(kDist + d * v * v, 1e-9));
    CHECK_THAT(far.theta, WithinAbs(0.0, 1e-12));
    // Back: the return leg slides on backwards by the same amount.
    CHECK_THAT(Last(run).x, WithinAbs(0.0, 1e-9));
  }
  for (const auto& run : Traj(c, 0).runs) {
    // Every spot turn turns on by a w^2 in its own sense; the legs slide
    // along the heading, so the heading changes only at the turns.
    const double sign = run.direction == "cw" ? -1.0 : 1.0;
    CHECK_THAT(Last(run).theta, WithinAbs(sign * (2.0 * kPi + 4.0 * a * w * w), 1e-9));
    const Pose2 after_leg = AtOrBefore(run, o.pause_s + kSide / v + 0.5 * o.pause_s);
    CHECK_THAT(after_leg.x, WithinAbs(kSide + d * v * v, 1e-9));
    CHECK_THAT(after_leg.y, WithinAbs(0.0, 1e-12));
  }
}

TEST_CASE("castor_swivel: kicks with the preceding turn's sign, a random sign after a reversal", "[effects][issue21]") {
  const double kappa = 0.01;
  sim::CampaignSimOptions o = testing::QuietOptions(10, 10);
  o.effects.swivel_kappa = kappa;
  const sim::SimulatedCampaign c = sim::SimulateCampaign(testing::QuietManifest(kB, kSide, kDist), o);
  for (const auto& run : Traj(c, 0).runs) {
    // Legs 2-4 follow a spot turn: three kicks with the turn's sign; the
    // first leg (from the run's start, no turn before it) does not kick.
    const double sign = run.direction == "cw" ? -1.0 : 1.0;
    CHECK_THAT(Last(run).theta, WithinAbs(sign * (2.0 * kPi + 3.0 * kappa), 1e-9));
    const Pose2 first_leg_end = AtOrBefore(run, o.pause_s + kSide / o.speed_m_s);
    CHECK_THAT(first_leg_end.y, WithinAbs(0.0, 1e-12));
  }
  int plus = 0, minus = 0;
  for (const auto& run : Traj(c, 1).runs) {
    // The reversal kicks +kappa or -kappa; the forward start does not.
    const double th = Last(run).theta;
    CHECK_THAT(std::abs(th), WithinAbs(kappa, 1e-12));
    (th > 0.0 ? plus : minus) += 1;
    const Pose2 far = AtOrBefore(run, o.pause_s + kDist / o.speed_m_s + 0.5 * o.pause_s);
    CHECK_THAT(far.theta, WithinAbs(0.0, 1e-12));
  }
  // Ten reversals: both signs (a fixed sign would be castor_kick's).
  CHECK(plus > 0);
  CHECK(minus > 0);
}

TEST_CASE("stop_slide, castor_swivel: bad parameters are refused with the allowed range", "[effects][issue21]") {
  CHECK(testing::EffectSpecError("stop_slide:d=-1").find("[0, 1] s^2/m") != std::string::npos);
  CHECK(testing::EffectSpecError("stop_slide:d=0.05,a=2").find("stop_slide.a = 2 must be in [0, 1] s^2/rad") != std::string::npos);
  CHECK(testing::EffectSpecError("stop_slide:d=nan").find("not a finite number; must be in [0, 1] s^2/m") != std::string::npos);
  CHECK(testing::EffectSpecError("castor_swivel:kappa=0.6").find("[-0.5, 0.5] rad") != std::string::npos);
  CHECK(testing::EffectSpecError("castor_swivel:kappa=inf").find("must be in [-0.5, 0.5] rad") != std::string::npos);
  CHECK(testing::EffectSpecError("castor_swivel:kappa=0.5").empty());
  CHECK(testing::EffectSpecError("stop_slide:d=0.06,a=0.01").empty());
  // Its shape (beyond the contract; 0 by default).
  CHECK(testing::EffectSpecError("stop_slide:d=0.06,arc=-1").find("stop_slide.arc = -1 must be in [0, 4]") != std::string::npos);
  CHECK(testing::EffectSpecError("stop_slide:d=0.06,arc=nan").find("must be in [0, 4]") != std::string::npos);
  CHECK(testing::EffectSpecError("stop_slide:d=0.06,back=-1").find("stop_slide.back = -1 must be in [-0.9, 4]") !=
        std::string::npos);
  CHECK(testing::EffectSpecError("stop_slide:d=0.06,a=0.01,arc=2,back=0.4").empty());

  using testing::Q;
  const auto dir = testing::TempDir("slide-cli");
  const auto in = dir / "in.toml";
  {
    std::ofstream f(in);
    f << "[robot]\nwheelbase_m = 0.3\nwheel_diameter_left_m = 0.08\nwheel_diameter_right_m = 0.08\n\n"
         "[[experiment]]\nkind = \"back_and_forth\"\ndistance_m = 1.0\nfile = \"bf.csv\"\n";
  }
  for (const char* bad : {"stop_slide:d=-1", "stop_slide:d=nan", "castor_swivel:kappa=0.7", "stop_slide:d=0.05,arc=5",
                          "stop_slide:d=0.05,back=inf"}) {
    const auto r = testing::RunCli("simulate " + Q(in) + " --out " + Q(dir / "x") + " --effect " + bad);
    INFO(bad << ": " << r.err);
    CHECK(r.status == 2);
    CHECK(r.err.find("must be in [") != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(dir / "x" / "campaign.toml"));
  }
}

TEST_CASE("diagnose model: replays stop_slide and castor_swivel exactly (noise-free)", "[diagnose][issue21]") {
  // Squares and figure-eights (no reversal, whose swivel sign is random),
  // wheel travel as distances, every other mean effect beside them.
  testing::SmallCampaign s = testing::MakeSmallCampaign(5, 2, 2);
  s.manifest.robot.ticks_per_rev.reset();
  s.manifest.experiments.pop_back();  // the back-and-forth runs
  testing::AddFreeExperiment(s.manifest, "free.csv");
  s.sim.free_runs = 2;
  s.sim.truth.k_L = s.sim.truth.k_R = 0.0;
  s.sim.ground_truth = GroundTruthNoise{0.0, 0.0};
  s.sim.effects.slide_d = 0.04;
  s.sim.effects.slide_a = 0.015;
  s.sim.effects.swivel_kappa = -0.007;
  s.sim.effects.scale_s = 0.01;
  s.sim.effects.castor_kappa = 0.004;
  s.sim.effects.time_tau = 0.02;
  const diag::CampaignData c = testing::BuildSmallCampaign(s);
  const diag::MeanModel model(c);
  diag::ParamVector p = TrueParams(s);
  double worst = Worst(model, p);
  // 10 micrometres: with the time offset the simulator reads the quadratic
  // coast between its 1 ms steps linearly (campaign_run.cpp Rest).
  CHECK(worst < 1e-5);
  // Without the two effects the residuals are millimetres.
  p[diag::kParamSlideD] = p[diag::kParamSlideA] = p[diag::kParamSwivel] = 0.0;
  CHECK(Worst(model, p) > 5e-3);
}

TEST_CASE("diagnose: a sliding stop is named stop_slide with d and a recovered, never a clock offset",
          "[diagnose][issue21]") {
  testing::SmallCampaign s = testing::MakeSmallCampaign(71, 5, 10);
  s.sim.effects.slide_d = 0.03;   // 7.5 mm after a leg at 0.5 m/s
  s.sim.effects.slide_a = 0.008;  // 8 mrad after a spot turn at 1 rad/s
  const diag::DiagnoseSummary d = diag::Diagnose(testing::BuildSmallCampaign(s), Fast());
  CHECK(d.verdict == "stop_slide");
  const diag::Candidate* c = Find(d, sim::EffectKind::kStopSlide);
  REQUIRE(c);
  CHECK_THAT(c->params.at("d"), WithinAbs(0.03, 5.0 * c->param_se.at("d")));
  CHECK(c->param_se.at("d") < 0.005);
  // Every spot turn of these squares has the same angle and rate: the turn
  // slide a w^2 is a constant extra turn, E_b's footprint, told apart only
  // where the samples catch the 16 ms coast after a turn. Either a is
  // fitted, or it is not and E_b takes it: 1 / E_b' = 1 / E_b + a w^2 /
  // (pi / 2), true E_b 1.012, a w^2 = 8 mrad: E_b' = 1.0068.
  CHECK_THAT(d.baseline.E_b, WithinAbs(1.0 / (1.0 / 1.012 + 0.008 / (kPi / 2.0)), 2e-3));
  if (c->params.count("a")) {
    CHECK_THAT(c->params.at("a"), WithinAbs(0.008, 5.0 * c->param_se.at("a")));
  } else {
    CHECK(c->note.find("turn part a is not fitted") != std::string::npos);
  }
  CHECK(c->heldout_shrink > 0.5);
  for (const std::string& e : d.verdict_effects) {
    CHECK(e != "time_offset");
    CHECK(e != "run_time_offset");
  }
  // The clock offset the slide imitates is not on the moving samples.
  const diag::Candidate* t = Find(d, sim::EffectKind::kTimeOffset);
  REQUIRE(t);
  CHECK(t->clock.checked);
  CHECK_FALSE(t->clock.supported);
}

TEST_CASE("diagnose: a turn slide is fitted when spot turns differ in rate", "[diagnose][issue21]") {
  // Figure-eights beside the squares do not help (arcs have no turn slide);
  // a campaign whose squares turn at two rates does: the slide a w^2 then
  // differs between turns of one angle, unlike a wheelbase error.
  testing::SmallCampaign s = testing::MakeSmallCampaign(83, 5, 6);
  s.sim.effects.slide_d = 0.03;
  s.sim.effects.slide_a = 0.01;
  sim::SimulatedCampaign fast = sim::SimulateCampaign(s.manifest, s.sim);
  s.sim.turn_rate_rad_s = 2.0;
  s.sim.seed = 84;
  const sim::SimulatedCampaign faster = sim::SimulateCampaign(s.manifest, s.sim);
  // Experiment 3: the squares turned at 2 rad/s.
  Manifest m = fast.manifest;
  Experiment extra = m.experiments.front();
  extra.file = extra.resolved_file = "square_fast.csv";
  m.experiments.push_back(extra);
  fast.data.push_back(faster.data.front());
  const diag::DiagnoseSummary d = diag::Diagnose(diag::BuildCampaign(m, fast.data), Fast());
  const diag::Candidate* c = Find(d, sim::EffectKind::kStopSlide);
  REQUIRE(c);
  REQUIRE(c->params.count("a") == 1);
  CHECK_THAT(c->params.at("a"), WithinAbs(0.01, 5.0 * c->param_se.at("a")));
  CHECK_THAT(c->params.at("d"), WithinAbs(0.03, 5.0 * c->param_se.at("d")));
  CHECK(d.verdict == "stop_slide");
}

TEST_CASE("diagnose: a real clock offset is carried by the moving samples", "[diagnose][issue21]") {
  testing::SmallCampaign s = testing::MakeSmallCampaign(73, 5, 10);
  s.sim.effects.time_tau = 0.03;
  const diag::DiagnoseSummary d = diag::Diagnose(testing::BuildSmallCampaign(s), Fast());
  CHECK(d.verdict == "time_offset");
  const diag::Candidate* t = Find(d, sim::EffectKind::kTimeOffset);
  REQUIRE(t);
  CHECK(t->clock.checked);
  CHECK(t->clock.supported);
  CHECK_THAT(t->clock.value, WithinAbs(0.03, 5.0 * t->clock.se));
  CHECK(t->clock.text.find("moving samples carry the evidence") != std::string::npos);
}

TEST_CASE("diagnose: a swivel castor is named castor_swivel with kappa recovered", "[diagnose][issue21]") {
  testing::SmallCampaign s = testing::MakeSmallCampaign(79, 5, 10);
  s.sim.effects.swivel_kappa = 0.008;
  const diag::DiagnoseSummary d = diag::Diagnose(testing::BuildSmallCampaign(s), Fast());
  CHECK(d.verdict == "castor_swivel");
  const diag::Candidate* c = Find(d, sim::EffectKind::kCastorSwivel);
  REQUIRE(c);
  CHECK_THAT(c->params.at("kappa"), WithinAbs(0.008, 5.0 * c->param_se.at("kappa")));
  CHECK(c->heldout_shrink > 0.5);
}

TEST_CASE("stop_slide's shape: simulate's arc and back coasts are the diagnosis model's, and diagnose recovers them",
          "[diagnose][issue21]") {
  // Squares, back-and-forth runs (backward stops) and figure eights (arc
  // stops), noise-free: the model at the true parameters reproduces the
  // simulator's poses (the coast's 1 ms steps aside), and without the
  // shape it is millimetres and milliradians off.
  testing::SmallCampaign s = testing::MakeSmallCampaign(5, 2, 2);
  s.manifest.robot.ticks_per_rev.reset();
  testing::AddFreeExperiment(s.manifest, "free.csv");
  s.sim.free_runs = 2;
  s.sim.truth.k_L = s.sim.truth.k_R = 0.0;
  s.sim.ground_truth = GroundTruthNoise{0.0, 0.0};
  s.sim.effects.slide_d = 0.05;
  s.sim.effects.slide_a = 0.01;
  s.sim.effects.slide_arc = 2.0;
  s.sim.effects.slide_back = 0.4;
  const diag::CampaignData c = testing::BuildSmallCampaign(s);
  const diag::MeanModel model(c);
  diag::ParamVector p = TrueParams(s);
  CHECK(Worst(model, p) < 1e-5);
  // A backward leg at 0.5 m/s coasts 0.4 x 0.05 x 0.25 = 5 mm further.
  p[diag::kParamSlideBack] = 0.0;
  CHECK(Worst(model, p) > 4e-3);
  p[diag::kParamSlideBack] = 0.4;
  p[diag::kParamSlideArc] = 0.0;
  CHECK(Worst(model, p, /*heading_only=*/true) > 1e-3);  // the heading after an arc's coast: 2 w/v d v^2 = 2 d v w
}

TEST_CASE("diagnose recovers stop_slide's arc and back from a noisy campaign", "[diagnose][issue21]") {
  testing::SmallCampaign s = testing::MakeSmallCampaign(83, 5, 10);
  testing::AddFreeExperiment(s.manifest, "free.csv");
  s.sim.free_runs = 4;
  s.sim.sample_rate_hz = 50.0;
  s.sim.effects.slide_d = 0.04;
  s.sim.effects.slide_a = 0.01;
  s.sim.effects.slide_arc = 2.0;
  s.sim.effects.slide_back = 0.5;
  const diag::DiagnoseSummary d = diag::Diagnose(testing::BuildSmallCampaign(s), Fast());
  INFO(d.verdict_reason);
  CHECK(d.verdict == "stop_slide");
  const diag::Candidate* c = Find(d, sim::EffectKind::kStopSlide);
  REQUIRE(c);
  REQUIRE(c->params.count("arc"));
  REQUIRE(c->params.count("back"));
  CHECK_THAT(c->params.at("d"), WithinAbs(0.04, 5.0 * c->param_se.at("d")));
  CHECK_THAT(c->params.at("back"), WithinAbs(0.5, 5.0 * c->param_se.at("back")));
  CHECK_THAT(c->params.at("arc"), WithinAbs(2.0, 5.0 * c->param_se.at("arc")));
  CHECK(c->param_se.at("back") < 0.1);
  CHECK(c->param_se.at("arc") < 0.5);
}

