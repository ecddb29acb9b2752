// Diagnosis tests on simulated campaigns with a known truth: the model
// reproduces the simulator's effects exactly (noise-free), its covariance
// matches Monte Carlo scatter, the noise fit recovers k_L, k_R, the gap's
// p-value is calibrated on clean campaigns, known effects are found and
// their parameters recovered, unidentifiable effects are reported as such,
// an effect outside the list is `unexplained`, and the command writes the
// contract's JSON.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include <nlohmann/json.hpp>

#include "diagnosis/pieces.hpp"
#include "diagnosis/diagnose.hpp"
#include "diagnosis/gap_stats.hpp"
#include "diagnosis/mean_fit.hpp"
#include "diagnosis/model.hpp"
#include "diagnosis/piece_noise.hpp"
#include "evaluation/data_warnings.hpp"
#include "formats/campaign_writer.hpp"
#include "simulation/campaign_sim.hpp"
#include "support/diag_campaign.hpp"
#include "support/run_cli.hpp"

using namespace umbmark;
using namespace umbmark::diag;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

/// A small campaign: `square_runs` cw and ccw squares of 2 m, `bf_runs`
/// back-and-forth runs of 2 m, optionally 3 figure-eights; 10 Hz, 0.5 m/s.
struct Small {
  Manifest manifest;
  sim::CampaignSimOptions sim;
};

Small MakeSmall(std::uint64_t seed, int square_runs = 5, int bf_runs = 10, bool free = false, bool ticks = true) {
  const testing::SmallCampaign base = testing::MakeSmallCampaign(seed, square_runs, bf_runs);
  Small s{base.manifest, base.sim};
  if (!ticks) s.manifest.robot.ticks_per_rev.reset();
  if (free) testing::AddFreeExperiment(s.manifest, "free.csv");
  s.sim.free_runs = 3;
  return s;
}

CampaignData Build(const Small& s) {
  const sim::SimulatedCampaign c = sim::SimulateCampaign(s.manifest, s.sim);
  return BuildCampaign(c.manifest, c.data);
}

DiagnoseOptions Fast(std::uint64_t seed = 1) {
  DiagnoseOptions o;
  o.null_simulations = 100;
  o.seed = seed;
  o.threads = 2;
  o.pieces.folds = 4;
  return o;
}

const Candidate* Find(const DiagnoseSummary& s, sim::EffectKind k) {
  for (const auto& c : s.candidates)
    if (c.effect == k) return &c;
  return nullptr;
}

ParamVector TrueParams(const Small& s) {
  ParamVector p = NominalParams();
  p[kParamEd] = s.sim.truth.E_d;
  p[kParamEb] = s.sim.truth.E_b;
  p[kParamScale] = s.sim.effects.scale_s;
  p[kParamScrub] = s.sim.effects.scrub_k;
  p[kParamAsym] = s.sim.effects.asymmetry_a;
  p[kParamKappa] = s.sim.effects.castor_kappa;
  p[kParamDrift] = s.sim.effects.drift_r;
  p[kParamDx] = s.sim.effects.gt_dx;
  p[kParamDy] = s.sim.effects.gt_dy;
  p[kParamTau] = s.sim.effects.time_tau;
  return p;
}

/// No wheel or ground-truth noise, every mean effect of the contract.
void NoiseFreeWithAllMeanEffects(Small& s) {
  s.sim.truth.k_L = s.sim.truth.k_R = 0.0;
  s.sim.ground_truth = GroundTruthNoise{0.0, 0.0};
  s.sim.effects.scale_s = 0.02;
  s.sim.effects.scrub_k = 0.05;
  s.sim.effects.asymmetry_a = -0.015;
  s.sim.effects.castor_kappa = 0.01;
  s.sim.effects.drift_r = 3e-4;
  s.sim.effects.gt_dx = 0.03;
  s.sim.effects.gt_dy = -0.02;
  s.sim.effects.time_tau = 0.037;
}

}  // namespace

TEST_CASE("diagnose model: replays every mean effect exactly (noise-free)", "[diagnose]") {
  // All mean effects at once, no noise, wheel travel as distances: the
  // model's pieces must match the simulator's ground truth to rounding.
  Small s = MakeSmall(3, 2, 2, true, false);
  NoiseFreeWithAllMeanEffects(s);
  const CampaignData c = Build(s);
  const MeanModel model(c);
  std::vector<double> eps;
  model.Residuals(TrueParams(s), eps);
  double worst = 0.0;
  for (double e : eps) worst = std::max(worst, std::abs(e));
  CHECK(worst < 1e-8);
  // ...and the nominal model is far off.
  model.Residuals(NominalParams(), eps);
  double nominal = 0.0;
  for (double e : eps) nominal = std::max(nominal, std::abs(e));
  CHECK(nominal > 1e-2);
}

TEST_CASE("diagnose model: a clock scan gives each tau's residuals as Residuals does", "[diagnose]") {
  Small s = MakeSmall(3, 2, 2, true, false);
  NoiseFreeWithAllMeanEffects(s);
  const CampaignData c = Build(s);
  const MeanModel model(c);
  const ParamVector truth = TrueParams(s);
  const std::vector<double> taus{-0.2, 0.0, 0.037, 0.11};
  std::vector<std::vector<double>> scan;
  model.ResidualsAtClocks(truth, taus, scan);
  REQUIRE(scan.size() == taus.size());
  for (std::size_t k = 0; k < taus.size(); ++k) {
    ParamVector p = truth;
    p[kParamTau] = taus[k];
    std::vector<double> eps;
    model.Residuals(p, eps);
    REQUIRE(scan[k].size() == eps.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < eps.size(); ++i) worst = std::max(worst, std::abs(scan[k][i] - eps[i]));
    CHECK(worst < 1e-12);
  }
}

TEST_CASE("diagnose model: a 0.29 s clock is fitted exactly from the scan's start", "[diagnose]") {
  // Noise-free, every mean effect, a clock of almost six 20 Hz sample
  // intervals, E_d, E_b and tau fitted from nominal and tau = 0: the scan's
  // start (mean_fit.hpp) must not move the fit off the true clock. (On the
  // simulator's smooth wheel rates a local fit from 0 finds it too; the
  // dips the scan steps over come with a real robot's jittery encoder
  // counts: bench/injection_recovery.sh.)
  Small s = MakeSmall(3, 2, 2, true, false);
  NoiseFreeWithAllMeanEffects(s);
  s.sim.effects.time_tau = 0.29;
  const CampaignData c = Build(s);
  const MeanModel model(c);
  ParamVector start = TrueParams(s);
  start[kParamTau] = 0.0;
  start[kParamEd] = start[kParamEb] = 1.0;
  const std::vector<Eigen::Matrix3d> W(c.pieces.size(), Eigen::Matrix3d::Identity() * 1e3);
  const MeanFit f = FitMean(model, start, {kParamEd, kParamEb, kParamTau}, W, MeanFitOptions{12});
  CHECK(f.p[kParamTau] == Approx(0.29).margin(1e-5));
  CHECK(f.p[kParamEd] == Approx(s.sim.truth.E_d).margin(1e-6));
  CHECK(f.p[kParamEb] == Approx(s.sim.truth.E_b).margin(1e-6));
  MeanFitOptions bad;
  bad.clock_step_s = 0.0;
  CHECK(bad.Check().find("clock_step_s") != std::string::npos);
  CHECK(MeanFitOptions{}.Check().empty());
}

TEST_CASE("diagnose campaign: motions are measured from/to the standstills' mean pose", "[diagnose]") {
  // No wheel noise, no quantisation, 1 mm ground-truth noise: a straight
  // leg between two standstills of N_a, N_b samples scatters by
  // sigma^2 (1/N_a + 1/N_b) along the track, not 2 sigma^2.
  Small s = MakeSmall(13, 10, 20, false, false);
  s.sim.truth.k_L = s.sim.truth.k_R = 0.0;
  s.sim.ground_truth = GroundTruthNoise{1e-3, 1e-9};
  s.sim.pause_s = 1.0;  // 10 samples at 10 Hz
  PieceOptions po;
  po.max_piece_length_m = 3.0;  // every 2 m leg one piece
  const sim::SimulatedCampaign sc = sim::SimulateCampaign(s.manifest, s.sim);
  const CampaignData c = BuildCampaign(sc.manifest, sc.data, po);
  const MeanModel model(c);
  std::vector<double> eps;
  model.Residuals(TrueParams(s), eps);
  double sum_sq = 0.0, sum_expected = 0.0;
  int averaged = 0;
  for (std::size_t j = 0; j < c.pieces.size(); ++j) {
    const Piece& p = c.pieces[j];
    if (p.type != PieceType::kStraight || p.a_lo == p.a_hi || p.b_lo == p.b_hi) continue;
    ++averaged;
    const DiagRun& r = c.runs[p.run];
    int na = 0, nb = 0;
    for (std::size_t i = p.a_lo; i <= p.a_hi; ++i) na += r.has_gt[i];
    for (std::size_t i = p.b_lo; i <= p.b_hi; ++i) nb += r.has_gt[i];
    REQUIRE(na >= 5);
    CHECK(p.a_hi == p.a);  // the standstill ends where the motion starts
    CHECK(p.b_lo == p.b);
    CHECK_THAT(p.a_weight, WithinRel(1.0 / na, 1e-12));
    CHECK_THAT(p.b_weight, WithinRel(1.0 / nb, 1e-12));
    sum_sq += eps[3 * j] * eps[3 * j];
    sum_expected += 1e-6 * (p.a_weight + p.b_weight);
  }
  REQUIRE(averaged >= 100);  // 4 legs x 20 squares + 2 legs x 20 back-and-forth
  // Mean square over >= 100 pieces: within 4 sd of a chi^2 mean (sqrt(2/n)).
  CHECK_THAT(sum_sq / sum_expected, WithinAbs(1.0, 4.0 * std::sqrt(2.0 / averaged)));
  CHECK(sum_sq / averaged < 0.5 * 2e-6);  // far below single samples' 2 sigma^2
}

TEST_CASE("diagnose model: legs and turns back to back (no pause) replay exactly", "[diagnose]") {
  // No standstill between motions: the junction intervals (one motion
  // ending, the next starting inside one sample interval) stay out of the
  // pieces, and every piece is reproduced to rounding, effects included.
  Small s = MakeSmall(5, 2, 2, false, false);
  s.sim.pause_s = 0.0;
  NoiseFreeWithAllMeanEffects(s);  // time_offset: samples near a junction show it (PoseAt splits it)
  const CampaignData c = Build(s);
  int turns = 0, stands = 0, junctions = 0;
  for (const DiagRun& r : c.runs) junctions += static_cast<int>(r.junctions.size());
  CHECK(junctions > 10);  // leg/turn junctions inside a sample interval (some fall on a sample)
  for (const Piece& p : c.pieces) {
    turns += p.type == PieceType::kTurn;
    stands += p.type == PieceType::kStand;
  }
  CHECK(turns == 2 * 2 * 4);  // every spot turn of the 4 squares found
  CHECK(stands <= 2 * 6);     // only at the starts and ends of runs
  const MeanModel model(c);
  std::vector<double> eps;
  model.Residuals(TrueParams(s), eps);
  double worst = 0.0;
  std::size_t worst_piece = 0;
  for (std::size_t i = 0; i < eps.size(); ++i)
    if (std::abs(eps[i]) > worst) {
      worst = std::abs(eps[i]);
      worst_piece = i / 3;
    }
  INFO("worst piece " << worst_piece << ": " << PieceTypeToString(c.pieces[worst_piece].type));
  CHECK(worst < 1e-8);
}

TEST_CASE("diagnose: no pauses between motions: clean campaigns raise no alarm", "[diagnose]") {
  int alarms = 0;
  for (int i = 0; i < 4; ++i) {
    Small s = MakeSmall(140 + static_cast<std::uint64_t>(i), 4, 8);
    s.sim.pause_s = 0.0;
    DiagnoseOptions o = Fast(3 + static_cast<std::uint64_t>(i));
    const DiagnoseSummary d = Diagnose(Build(s), o);
    alarms += d.verdict != "none";
  }
  // At alpha = 1 %, P(>= 2 alarms of 4) < 6e-4.
  CHECK(alarms <= 1);
}

TEST_CASE("diagnose model: piece covariance matches Monte Carlo scatter", "[diagnose]") {
  // At the true parameters the whitened scores of many noisy runs have unit
  // variance and no correlation (eq. 4 noise, ground-truth noise and
  // quantisation, 2000+ pieces: sample variance within ~10 %).
  Small s = MakeSmall(11, 15, 30);
  s.manifest.robot.ticks_per_rev = 1024;  // coarse ticks: quantisation matters
  const CampaignData c = Build(s);
  const MeanModel model(c);
  std::vector<double> eps;
  const ParamVector p = TrueParams(s);
  model.Residuals(p, eps);
  const std::vector<PieceBases> bases = ComputeBases(c, model, p);
  NoiseParams n;
  n.kL2 = s.sim.truth.k_L * s.sim.truth.k_L;
  n.kR2 = s.sim.truth.k_R * s.sim.truth.k_R;
  n.sxy2 = 3e-4 * 3e-4;
  n.sth2 = 1.5e-3 * 1.5e-3;
  const std::vector<Scores> z = PieceScores(eps, bases, c.pieces, n);
  for (PieceType type : {PieceType::kStraight, PieceType::kTurn, PieceType::kStand}) {
    double sq[3] = {0, 0, 0}, prod = 0;
    int count = 0;
    for (std::size_t j = 0; j < z.size(); ++j) {
      if (c.pieces[j].type != type) continue;
      ++count;
      for (int k = 0; k < 3; ++k) sq[k] += z[j][k] * z[j][k];
      prod += z[j][0] * z[j][2];
    }
    INFO(PieceTypeToString(type) << ": " << count << " pieces");
    REQUIRE(count > 100);
    const double tol = 4.0 * std::sqrt(2.0 / count);
    for (int k = 0; k < 3; ++k) CHECK_THAT(sq[k] / count, WithinAbs(1.0, tol));
    CHECK_THAT(prod / count, WithinAbs(0.0, 4.0 / std::sqrt(count)));
  }
}

TEST_CASE("diagnose: clean campaign: baseline recovered, no gap", "[diagnose]") {
  const Small s = MakeSmall(21);
  const CampaignData c = Build(s);
  const DiagnoseSummary d = Diagnose(c, Fast());
  CHECK(d.verdict == "none");
  CHECK(d.p_value > 0.01);
  CHECK_THAT(d.baseline.E_d, WithinAbs(1.004, 3e-4));
  CHECK_THAT(d.baseline.E_b, WithinAbs(1.012, 2e-3));
  CHECK_THAT(d.baseline.k_L, WithinRel(1.5e-3, 0.3));
  CHECK_THAT(d.baseline.k_R, WithinRel(2.5e-3, 0.3));
  CHECK(d.baseline.returns.size() == 3);  // cw, ccw, fwd_back
  // turn_scrub is E_b without arcs, up to the spot turns' small forward
  // motion: weakly identifiable at most, and reported as such.
  const Candidate* scrub = Find(d, sim::EffectKind::kTurnScrub);
  REQUIRE(scrub);
  CHECK((!scrub->identifiable || scrub->weak));
  bool listed = false;
  for (const auto& t : d.indistinguishable) listed = listed || t.find("turn_scrub") != std::string::npos;
  CHECK(listed);
}

TEST_CASE("diagnose: ground truth noise is estimated when the manifest does not state it", "[diagnose]") {
  Small s = MakeSmall(23);
  s.sim.ground_truth = GroundTruthNoise{4e-4, 2e-3};
  s.sim.state_ground_truth = false;
  const CampaignData c = Build(s);
  REQUIRE_FALSE(c.ground_truth);
  DiagnoseOptions o = Fast();
  o.effects = {sim::EffectKind::kScaleError};
  SECTION("default: the scatter inside the standstills, held fixed") {
    // Issue 28: the baseline takes the standstill scatter. This campaign
    // has 80 differences per component at lag 1 (160 position values):
    // the robust sd's sampling error is about 1.17 / sqrt(n), 13 % for
    // heading, 9.2 % for position; 3 of those is the bound. The fit on the
    // pieces (the old estimate, still reported) keeps its 15 %.
    const DiagnoseSummary d = Diagnose(c, o);
    CHECK(d.baseline.ground_truth_estimated);
    CHECK(d.baseline.ground_truth_source == "standstills");
    REQUIRE(d.baseline.standstill.measured);
    CHECK(d.baseline.sigma_xy_m == Approx(d.baseline.standstill.sigma_xy_m).epsilon(1e-12));
    CHECK(d.baseline.sigma_theta_rad == Approx(d.baseline.standstill.sigma_theta_rad).epsilon(1e-12));
    CHECK_THAT(d.baseline.sigma_xy_m, WithinRel(4e-4, 0.28));
    CHECK_THAT(d.baseline.sigma_theta_rad, WithinRel(2e-3, 0.39));
    CHECK_THAT(d.baseline.pieces_sigma_xy_m, WithinRel(4e-4, 0.15));
    CHECK_THAT(d.baseline.pieces_sigma_theta_rad, WithinRel(2e-3, 0.15));
    CHECK(d.verdict == "none");
  }
  SECTION("--fit-ground-truth-noise: fitted with the wheel noise on the pieces, as before issue 28") {
    o.baseline_fit.ground_truth = GroundTruthNoiseSource::kFitted;
    const DiagnoseSummary d = Diagnose(c, o);
    CHECK(d.baseline.ground_truth_estimated);
    CHECK(d.baseline.ground_truth_source == "fitted");
    CHECK_THAT(d.baseline.sigma_xy_m, WithinRel(4e-4, 0.15));
    CHECK_THAT(d.baseline.sigma_theta_rad, WithinRel(2e-3, 0.15));
    CHECK(d.verdict == "none");
  }
}

TEST_CASE("diagnose: p-value is calibrated on campaigns from the baseline itself", "[diagnose]") {
  // 16 clean campaigns: G's p-values and every likelihood-ratio test's
  // p-value should look uniform. P(>= 5 of 16 below 0.1) = 0.017 and the
  // mean of 16 uniforms is 0.5 +- 0.072 (bound: 3 sd). The combined p is
  // conservative (Bonferroni): at most as many alarms.
  int below = 0, combined_below = 0;
  double sum = 0.0;
  std::map<std::string, std::pair<int, double>> lr;  // effect -> (below 0.1, sum of p)
  const int campaigns = 16;
  for (int i = 0; i < campaigns; ++i) {
    Small s = MakeSmall(100 + static_cast<std::uint64_t>(i), 3, 6);
    s.sim.truth.E_d = 1.0 + 0.002 * (i % 3);
    DiagnoseOptions o = Fast(7 + static_cast<std::uint64_t>(i));
    o.null_simulations = 60;
    o.effects = {sim::EffectKind::kScaleError, sim::EffectKind::kCastorKick, sim::EffectKind::kCorrelatedNoise};
    const DiagnoseSummary d = Diagnose(Build(s), o);
    below += d.score_p_value < 0.1;
    combined_below += d.p_value < 0.1;
    sum += d.score_p_value;
    CHECK(d.tests == 3);
    for (const Candidate& c : d.candidates) {
      REQUIRE(c.tested);
      auto& [n, ps] = lr[sim::EffectToString(c.effect)];
      n += c.lr_p_value < 0.1;
      ps += c.lr_p_value;
    }
  }
  CHECK(below <= 4);
  CHECK(combined_below <= 4);
  CHECK_THAT(sum / campaigns, WithinAbs(0.5, 0.22));
  REQUIRE(lr.size() == 3);
  for (const auto& [effect, v] : lr) {
    INFO(effect);
    CHECK(v.first <= 4);
    CHECK_THAT(v.second / campaigns, WithinAbs(0.5, 0.22));
  }
}

TEST_CASE("diagnose: gt_offset is found and its offset recovered", "[diagnose]") {
  Small s = MakeSmall(31);
  s.sim.effects.gt_dx = 0.025;
  s.sim.effects.gt_dy = -0.015;
  const DiagnoseSummary d = Diagnose(Build(s), Fast());
  CHECK(d.significant);
  CHECK(d.verdict == "gt_offset");
  const Candidate* c = Find(d, sim::EffectKind::kGtOffset);
  REQUIRE(c);
  CHECK_THAT(c->params.at("dx"), WithinAbs(0.025, 5.0 * c->param_se.at("dx")));
  CHECK_THAT(c->params.at("dy"), WithinAbs(-0.015, 5.0 * c->param_se.at("dy")));
  CHECK(c->param_se.at("dx") < 0.003);
  CHECK(c->shrink > 0.8);
  CHECK(c->heldout_shrink > 0.5);
  // The strongest discrepancy is in the spot turns (where the offset point moves).
  REQUIRE_FALSE(d.where.empty());
  CHECK(d.where.front().subset.find("spot turn") != std::string::npos);
}

TEST_CASE("diagnose: castor_kick is found, kappa recovered", "[diagnose]") {
  Small s = MakeSmall(41);
  s.sim.effects.castor_kappa = -0.008;
  const DiagnoseSummary d = Diagnose(Build(s), Fast());
  CHECK(d.verdict == "castor_kick");
  const Candidate* c = Find(d, sim::EffectKind::kCastorKick);
  REQUIRE(c);
  CHECK_THAT(c->params.at("kappa"), WithinAbs(-0.008, 5.0 * c->param_se.at("kappa")));
  CHECK(c->heldout_shrink > 0.5);
}

TEST_CASE("diagnose: direction_asymmetry is found on the backward legs", "[diagnose]") {
  Small s = MakeSmall(43);
  s.sim.effects.asymmetry_a = 0.012;
  const DiagnoseSummary d = Diagnose(Build(s), Fast());
  CHECK(d.verdict == "direction_asymmetry");
  const Candidate* c = Find(d, sim::EffectKind::kDirectionAsymmetry);
  REQUIRE(c);
  CHECK_THAT(c->params.at("a"), WithinAbs(0.012, 5.0 * c->param_se.at("a")));
}

TEST_CASE("diagnose: turn_scrub needs arcs: found with figure-eights", "[diagnose]") {
  Small s = MakeSmall(51, 5, 10, true);
  s.sim.effects.scrub_k = 0.05;
  const DiagnoseSummary d = Diagnose(Build(s), Fast());
  const Candidate* c = Find(d, sim::EffectKind::kTurnScrub);
  INFO(d.verdict_reason);
  INFO(DiagnoseToJson(d).at("explanation").dump());
  REQUIRE(c);
  CHECK(c->identifiable);
  CHECK(d.verdict == "turn_scrub");
  CHECK_THAT(c->params.at("k"), WithinAbs(0.05, 5.0 * c->param_se.at("k")));
  // With scrub in the model, E_b returns to the true wheelbase error.
  CHECK_THAT(c->E_b, WithinAbs(1.012, 3e-3));
}

TEST_CASE("diagnose: a turn scrub fitted 2 SE below 0 is a symptom in the explanation too, never a step",
          "[diagnose]") {
  // Scrubbing only loses rotation (k >= 0). A slightly negative k (here
  // -0.006, above advice.hpp's fixed floor of -0.01) is flagged by its
  // standard error; the explanation's joint fits take the single-effect
  // fit's SE. Before that they had none, and the June campaign named such
  // a scrub (k = -0.0062) while its candidate was flagged impossible.
  // Issue 28 (item 5): an impossible fit is a symptom, never a step: it is
  // listed among the explanation's symptoms (JSON `symptoms`), not its
  // steps (until then it was a step marked `unphysical`).
  Small s = MakeSmall(51, 5, 10, true);
  s.manifest.ground_truth = GroundTruthNoise{1e-4, 5e-4};
  s.sim.effects.scrub_k = -0.006;
  const DiagnoseSummary d = Diagnose(Build(s), Fast());
  const Candidate* c = Find(d, sim::EffectKind::kTurnScrub);
  REQUIRE(c);
  INFO(d.verdict_reason);
  INFO("k = " << c->params.at("k") << " +- " << c->param_se.at("k"));
  CHECK_THAT(c->params.at("k"), WithinAbs(-0.006, 4.0 * c->param_se.at("k")));
  REQUIRE(c->params.at("k") + 2.0 * c->param_se.at("k") < 0.0);
  REQUIRE(c->params.at("k") > -0.01);
  // Slightly below 0 (above the fixed floor): a symptom, but its
  // likelihood-ratio test still shows the gap (verdict.cpp).
  CHECK_FALSE(c->impossible);
  for (const ExplanationStep& st : d.explanation) CHECK(st.effect != sim::EffectKind::kTurnScrub);
  bool symptom = false;
  for (const ExplanationStep& st : d.symptoms)
    if (st.effect == sim::EffectKind::kTurnScrub) {
      symptom = true;
      CHECK(st.unphysical.find("negative turn scrub") != std::string::npos);
    }
  CHECK(symptom);
  CHECK(std::find(d.verdict_effects.begin(), d.verdict_effects.end(), "turn_scrub") == d.verdict_effects.end());
  CHECK(d.verdict != "turn_scrub");
  const nlohmann::json j = DiagnoseToJson(d);
  bool flagged = false;
  for (const auto& st : j.at("symptoms"))
    flagged = flagged || (st.at("effect") == "turn_scrub" && st.at("why").get<std::string>().find("negative") !=
                                                                 std::string::npos);
  CHECK(flagged);
}

TEST_CASE("diagnose: turn_scrub without arcs: told from E_b by the spot turns' forward motion", "[diagnose]") {
  // With E_d far from 1 a spot turn moves the axle forward by
  // (c_R - c_L) b phi / 4; a wheelbase error E_b = 1/(1 - k) reproduces the
  // turn angles only with a diameter ratio that makes this (1 - k) times too
  // large. The likelihood-ratio test sees it where the gap score cannot.
  Small s = MakeSmall(57, 10, 10);
  s.manifest.ground_truth = GroundTruthNoise{1e-4, 5e-4};
  s.sim.truth.E_d = 1.012;
  s.sim.truth.k_L = s.sim.truth.k_R = 5e-4;
  s.sim.effects.scrub_k = 0.1;
  const DiagnoseSummary d = Diagnose(Build(s), Fast());
  const Candidate* c = Find(d, sim::EffectKind::kTurnScrub);
  REQUIRE(c);
  CHECK(c->identifiable);
  CHECK(c->tested);
  CHECK(d.significant);
  CHECK(d.verdict == "turn_scrub");
  CHECK_THAT(c->params.at("k"), WithinAbs(0.1, 4.0 * c->param_se.at("k")));
  CHECK(c->param_se.at("k") < 0.05);
  // E_b with the scrub is the true wheelbase error, up to k's uncertainty
  // (the two move together: E_b (1 - k) is what the turns see).
  INFO("k = " << c->params.at("k") << " +- " << c->param_se.at("k") << ", E_b = " << c->E_b);
  CHECK_THAT(c->E_b, WithinAbs(1.012, 4.0 * 1.012 * c->param_se.at("k")));
}

TEST_CASE("diagnose: endpoint-only squares cannot separate scale_error from E_b", "[diagnose]") {
  Small s = MakeSmall(61, 8, 10);
  s.manifest.experiments.pop_back();  // squares only
  s.sim.endpoint_squares = true;
  s.sim.effects.scale_s = 0.02;
  const CampaignData c = Build(s);
  REQUIRE(c.pieces.size() == 16);  // one return-error piece per run
  DiagnoseOptions o = Fast();
  const DiagnoseSummary d = Diagnose(c, o);
  const Candidate* sc = Find(d, sim::EffectKind::kScaleError);
  REQUIRE(sc);
  CHECK((!sc->identifiable || sc->weak));
  bool listed = false;
  for (const auto& t : d.indistinguishable) listed = listed || t.find("scale_error") != std::string::npos;
  CHECK(listed);
  CHECK(d.verdict != "scale_error");
}

TEST_CASE("diagnose: an effect outside the list is unexplained, not a confident wrong name", "[diagnose]") {
  Small s = MakeSmall(71);
  s.sim.effects.yaw_delta = 0.012;  // motion-capture yaw misalignment
  const DiagnoseSummary d = Diagnose(Build(s), Fast());
  CHECK(d.significant);
  CHECK(d.verdict == "unexplained");
}

// The verdict names what closes the larger part of the gap and reports the
// rest, unless the rest lies mostly in the runs' means (docs/diagnosis.md,
// "The verdict's rule"). A 2 % scale error on a robot whose motion capture
// is noisier than its manifest says (the stated noise is an unlisted
// misfit of the spread): scale_error is named, the remainder stated as
// significant in the JSON, a warning and the next steps. The same scale
// error beside a motion-capture yaw misalignment (an unlisted systematic
// cause): `unexplained`, the remainder in the runs' means.
TEST_CASE("diagnose: a listed effect beside an unlisted one: named when the rest is spread, not when it is systematic",
          "[diagnose]") {
  const double stated_xy = 3e-4, stated_theta = 1.5e-3;  // MakeSmall's manifest
  Small s = MakeSmall(71);
  s.sim.effects.scale_s = 0.02;
  s.manifest.ground_truth = GroundTruthNoise{1.7 * stated_xy, 1.7 * stated_theta};
  sim::SimulatedCampaign sc = sim::SimulateCampaign(s.manifest, s.sim);
  sc.manifest.ground_truth = GroundTruthNoise{stated_xy, stated_theta};
  const DiagnoseSummary d = Diagnose(BuildCampaign(sc.manifest, sc.data), Fast());
  INFO(d.verdict_reason);
  REQUIRE(d.significant);
  CHECK(d.verdict == "scale_error");
  CHECK(d.remainder_significant);
  // More than a tenth left held out: not the misfit of the scale error's
  // shape (full_shrink); before session 18 this verdict was `unexplained`.
  CHECK(d.unexplained_fraction > 1.0 - DiagnoseOptions{}.full_shrink);
  CHECK(d.unexplained_fraction <= 0.5);
  CHECK(d.remainder_mean_share < 0.5);
  CHECK(d.remaining_gap_score > d.null_quantile_alpha);
  const auto said = [](const std::vector<std::string>& v, const std::string& w) {
    return std::any_of(v.begin(), v.end(), [&](const std::string& x) { return x.find(w) != std::string::npos; });
  };
  CHECK(said(d.warnings, "no listed effect describes"));
  CHECK(said(d.next_steps, "no listed effect describes"));
  CHECK(d.summary.find("the rest is something no listed effect describes") != std::string::npos);
  CHECK(DiagnoseToJson(d).at("verdict").at("remainder_significant").get<bool>());

  Small y = MakeSmall(71);
  y.sim.effects.scale_s = 0.02;
  y.sim.effects.yaw_delta = 0.006;  // motion-capture yaw misalignment
  const DiagnoseSummary dy = Diagnose(Build(y), Fast());
  INFO(dy.verdict_reason);
  CHECK(dy.verdict == "unexplained");
  CHECK(dy.unexplained_fraction <= 0.5);  // the listed effects close the larger part...
  CHECK(dy.remainder_mean_share >= 0.5);  // ...but leave a systematic remainder
  CHECK(dy.verdict_reason.find("mostly in the runs' means") != std::string::npos);
}

TEST_CASE("umbmark diagnose: contract JSON, report, plot", "[diagnose][cli]") {
  using testing::Q;
  const auto dir = testing::TempDir("diagnose-cli");
  Small s = MakeSmall(81, 3, 6);
  s.sim.effects.time_tau = 0.06;
  const sim::SimulatedCampaign c = sim::SimulateCampaign(s.manifest, s.sim);
  const std::string manifest = io::WriteCampaign(c.manifest, c.data, (dir / "campaign").string());
  auto r = testing::RunCli("diagnose " + Q(manifest) + " --null-sims 100 --folds 3 --json " + Q(dir / "d.json") +
                           " --plot " + Q(dir / "gap.svg"));
  INFO(r.err);
  REQUIRE(r.status == 0);
  CHECK(r.out.find("Verdict: time_offset") != std::string::npos);
  const auto j = nlohmann::json::parse(testing::Slurp((dir / "d.json").string()));
  CHECK(j["gap"]["score"].is_number());
  CHECK(j["gap"]["p_value"].is_number());
  CHECK(j["gap"]["where"].is_array());
  REQUIRE_FALSE(j["gap"]["where"].empty());
  for (const char* k : {"experiment", "subset", "statistic", "size_se"}) CHECK(j["gap"]["where"][0].contains(k));
  REQUIRE(j["candidates"].size() == 14);  // every contract effect
  for (const auto& cd : j["candidates"]) {
    CHECK(cd["effect"].is_string());
    CHECK(cd["params"].is_object());
    CHECK(cd["shrink"].is_number());
    CHECK(cd["heldout_shrink"].is_number());
  }
  CHECK(j["candidates"][0]["effect"] == "time_offset");
  CHECK(j["verdict"]["effect"] == "time_offset");
  CHECK(testing::Slurp((dir / "gap.svg").string()).find("<svg") != std::string::npos);
  // --json - writes JSON alone.
  r = testing::RunCli("diagnose " + Q(manifest) + " --null-sims 20 --folds 2 --effects time_offset --json -");
  REQUIRE(r.status == 0);
  const auto one = nlohmann::json::parse(r.out);
  CHECK(one["verdict"]["effect"] == "time_offset");
  // The combined p-value: min(1, 2 min(p_G, tests' Bonferroni p)); with
  // --no-likelihood-tests the gap score's own.
  const double pg = one["gap"]["score_p_value"], pt = one["gap"]["tests_p_value"];
  CHECK(one["gap"]["tests"] == 1);
  CHECK_THAT(one["gap"]["p_value"].get<double>(), WithinRel(std::min(1.0, 2.0 * std::min(pg, pt)), 1e-9));
  r = testing::RunCli("diagnose " + Q(manifest) +
                      " --null-sims 20 --folds 2 --effects time_offset --no-likelihood-tests --json -");
  REQUIRE(r.status == 0);
  const auto alone = nlohmann::json::parse(r.out);
  CHECK_THAT(alone["gap"]["p_value"].get<double>(), WithinRel(alone["gap"]["score_p_value"].get<double>(), 1e-12));
  // Usage and input errors.
  CHECK(testing::RunCli("diagnose " + Q(manifest) + " --effects warp").status == 2);
  // A missing input file is bad input (exit 1, naming the file; issue 14), not a usage error.
  const auto missing = testing::RunCli("diagnose " + Q(dir / "missing.toml"));
  CHECK(missing.status == 1);
  CHECK(missing.err.find("missing.toml") != std::string::npos);
}

TEST_CASE("diagnose: two effects at once (castor kick + time offset) are both named, stepwise", "[diagnose][explanation]") {
  Small s = MakeSmall(61);
  s.sim.effects.castor_kappa = 0.008;
  s.sim.effects.time_tau = 0.04;
  const DiagnoseSummary d = Diagnose(Build(s), Fast());
  INFO(d.verdict_reason);
  REQUIRE(d.explanation.size() >= 2);
  CHECK(std::find(d.verdict_effects.begin(), d.verdict_effects.end(), "castor_kick") != d.verdict_effects.end());
  CHECK(std::find(d.verdict_effects.begin(), d.verdict_effects.end(), "time_offset") != d.verdict_effects.end());
  REQUIRE_FALSE(d.verdict_effects.empty());
  CHECK(d.verdict == d.verdict_effects.front());
  // Fitted jointly: both parameters recovered at the last step's fit.
  for (const auto& e : d.explanation) {
    if (e.effect == sim::EffectKind::kCastorKick) CHECK_THAT(e.params.at("kappa"), WithinAbs(0.008, 0.0008));
    if (e.effect == sim::EffectKind::kTimeOffset) CHECK_THAT(e.params.at("tau"), WithinAbs(0.04, 0.004));
  }
  // Cumulative shrink grows step by step and closes the gap.
  CHECK(d.explanation.back().cumulative_heldout_shrink > d.explanation.front().cumulative_heldout_shrink);
  CHECK(d.explanation.back().cumulative_heldout_shrink > 0.9);
  CHECK_THAT(d.unexplained_fraction, WithinAbs(1.0 - d.explanation.back().cumulative_heldout_shrink, 1e-12));
  const nlohmann::json j = DiagnoseToJson(d);
  CHECK(j.at("explanation").size() == d.explanation.size());
  CHECK(j.at("verdict").at("effects").size() == d.verdict_effects.size());
  CHECK(j.at("verdict").contains("unexplained_fraction"));
}

TEST_CASE("diagnose: an effect whose evidence given the others is not decisive stays a step, not named",
          "[diagnose][explanation]") {
  // Both causes earn far more than ln 100 given the other: named. Raising
  // the level just above what the weaker one earns leaves it a step,
  // reported as not decisive, and the stronger one the verdict.
  Small s = MakeSmall(61);
  s.sim.effects.castor_kappa = 0.008;
  s.sim.effects.time_tau = 0.04;
  DiagnoseOptions o = Fast();
  CHECK_THAT(o.decisive_nats, WithinAbs(std::log(100.0), 1e-12));
  DiagnoseSummary d = Diagnose(Build(s), o);
  INFO(d.verdict_reason);
  REQUIRE(d.explanation.size() >= 2);
  const ExplanationStep* weakest = nullptr;
  for (const ExplanationStep& e : d.explanation) {
    if (e.negligible || !e.unphysical.empty()) continue;
    CHECK(e.earned_given_others_nats >= o.decisive_nats);
    CHECK_FALSE(e.not_decisive);
    if (!weakest || e.earned_given_others_nats < weakest->earned_given_others_nats) weakest = &e;
  }
  REQUIRE(weakest != nullptr);
  // Copied: `d` is replaced below.
  const sim::EffectKind weak_effect = weakest->effect;
  const std::string weak_name = sim::EffectToString(weak_effect);
  const std::size_t named_before = d.verdict_effects.size();
  REQUIRE(named_before >= 2);
  o.decisive_nats = weakest->earned_given_others_nats + 1.0;
  weakest = nullptr;
  d = Diagnose(Build(s), o);
  INFO(d.verdict_reason);
  CHECK(d.verdict_effects.size() == named_before - 1);
  CHECK(std::find(d.verdict_effects.begin(), d.verdict_effects.end(), weak_name) == d.verdict_effects.end());
  CHECK(d.verdict != weak_name);
  CHECK(d.verdict_reason.find("not decisive given the other effects") != std::string::npos);
  CHECK(d.verdict_reason.find(weak_name + " (") != std::string::npos);
  bool flagged = false;
  for (const ExplanationStep& e : d.explanation) flagged = flagged || (e.effect == weak_effect && e.not_decisive);
  CHECK(flagged);
  const nlohmann::json j = DiagnoseToJson(d);
  bool json_flagged = false;
  for (const auto& e : j.at("explanation"))
    json_flagged = json_flagged || (e.at("effect") == weak_name && e.at("not_decisive").get<bool>());
  CHECK(json_flagged);
}

TEST_CASE("diagnose: a significant but sub-millimetre marker offset is negligible, never the verdict",
          "[diagnose][negligible]") {
  // Noise-free ground truth makes a 0.3 mm offset highly significant; next
  // to a run-to-run scatter of millimetres it does not matter.
  Small s = MakeSmall(62);
  s.sim.ground_truth = GroundTruthNoise{1e-5, 1e-4};
  s.sim.effects.gt_dx = 3e-4;
  DiagnoseSummary d = Diagnose(Build(s), Fast());
  INFO(d.verdict_reason);
  CHECK(d.verdict == "none");
  CHECK(d.verdict_effects.empty());
  if (d.significant) {
    REQUIRE_FALSE(d.explanation.empty());
    CHECK(d.explanation.front().negligible);
    CHECK(d.explanation.front().size_mm < 0.5);
  }
  // With the threshold at 0 the same offset is named.
  DiagnoseOptions o = Fast();
  o.negligible = 0.0;
  d = Diagnose(Build(s), o);
  if (d.significant) CHECK(d.verdict == "gt_offset");
}

TEST_CASE("diagnose: standstill_motion is found, sigmas recovered", "[diagnose][new-effects]") {
  Small s = MakeSmall(71);
  s.sim.effects.stand_sigma_xy = 0.004;
  s.sim.effects.stand_sigma_theta = 0.004;
  const DiagnoseSummary d = Diagnose(Build(s), Fast());
  INFO(d.verdict_reason);
  CHECK(d.verdict == "standstill_motion");
  const Candidate* c = Find(d, sim::EffectKind::kStandstillMotion);
  REQUIRE(c);
  // 20 runs x ~9 standstills: sigma within 25 %.
  CHECK_THAT(c->params.at("sigma_xy"), WithinRel(0.004, 0.25));
  CHECK_THAT(c->params.at("sigma_theta"), WithinRel(0.004, 0.25));
}

TEST_CASE("diagnose: standstill_motion is sized on the pieces it acts on (not every piece of their type)",
          "[diagnose][negligible][new-effects]") {
  // Figure-eights only: each circle is one motion from standstill to
  // standstill, cut into several arc pieces of which only the last ends at
  // the standstill. The effect widens that piece's position and heading sd
  // by sqrt(2) sigma_xy and sigma_theta exactly (S_xy = diag(1, 1, 0),
  // S_theta = e3 e3^T), so that is its size; the median over every arc
  // piece would be 0 (pieces it does not act on once counted through a
  // rounding residue of 1e-22 m^2, and the effect came out negligible).
  Small s = MakeSmall(75);
  s.manifest.experiments.clear();
  testing::AddFreeExperiment(s.manifest, "free.csv");
  s.sim.free_runs = 20;
  s.sim.effects.stand_sigma_xy = 0.004;
  s.sim.effects.stand_sigma_theta = 0.006;
  const DiagnoseSummary d = Diagnose(Build(s), Fast());
  INFO(d.verdict_reason);
  const auto step = std::find_if(d.explanation.begin(), d.explanation.end(),
                                 [](const ExplanationStep& e) { return e.effect == sim::EffectKind::kStandstillMotion; });
  REQUIRE(step != d.explanation.end());
  CHECK_FALSE(step->negligible);
  CHECK(step->size_pieces == "arc");
  CHECK(step->relative_size > 0.25);
  CHECK_THAT(step->size_mm, WithinRel(1e3 * std::sqrt(2.0) * step->params.at("sigma_xy"), 1e-6));
  CHECK_THAT(step->size_mrad, WithinRel(1e3 * step->params.at("sigma_theta"), 1e-6));
  // 40 standstills: sigma_theta within 35 % (3 sigma of the sd of 40 draws).
  CHECK_THAT(step->params.at("sigma_theta"), WithinRel(0.006, 0.35));
  CHECK(std::find(d.verdict_effects.begin(), d.verdict_effects.end(), "standstill_motion") != d.verdict_effects.end());
}

TEST_CASE("diagnose: motion_noise_floor is found, sigma recovered", "[diagnose][new-effects]") {
  Small s = MakeSmall(72);
  s.sim.effects.floor_sigma = 0.006;
  const DiagnoseSummary d = Diagnose(Build(s), Fast());
  INFO(d.verdict_reason);
  CHECK(d.verdict == "motion_noise_floor");
  const Candidate* c = Find(d, sim::EffectKind::kMotionNoiseFloor);
  REQUIRE(c);
  CHECK_THAT(c->params.at("sigma"), WithinRel(0.006, 0.3));
}

TEST_CASE("diagnose: run_time_offset is found, tau_sd recovered", "[diagnose][new-effects]") {
  Small s = MakeSmall(73, 10, 20);
  s.sim.effects.run_tau_sd = 0.05;
  const DiagnoseSummary d = Diagnose(Build(s), Fast());
  INFO(d.verdict_reason);
  INFO(DiagnoseToJson(d).at("candidates").dump());
  CHECK(d.verdict == "run_time_offset");
  const Candidate* c = Find(d, sim::EffectKind::kRunTimeOffset);
  REQUIRE(c);
  // 40 runs: the sd of 40 draws is within ~25 % of tau_sd (3 sigma).
  CHECK_THAT(c->params.at("tau_sd"), WithinRel(0.05, 0.35));
}

TEST_CASE("diagnose: a noise floor's size is the growth of the spread of the pieces it widens most",
          "[diagnose][negligible][new-effects]") {
  // motion_noise_floor adds N(0, sigma^2) to each wheel once per motion, so
  // a spot turn (one piece from standstill to standstill) gains a heading
  // sd of sqrt(2) sigma / b; a 2 m leg, split in two pieces, sigma / b per
  // piece. Against the wheel noise of a 90 deg turn (0.27 m per wheel) a
  // 2 mm floor widens the spread by more than half; 0.2 mm (fitted at
  // about 0.5 mm here, seed 74) by about an eighth: significant, negligible.
  const double b = 0.35;
  Small s = MakeSmall(74, 10, 20);
  s.sim.effects.floor_sigma = 0.002;
  DiagnoseSummary d = Diagnose(Build(s), Fast());
  INFO(d.verdict_reason);
  CHECK(d.verdict == "motion_noise_floor");
  REQUIRE_FALSE(d.explanation.empty());
  const ExplanationStep& healthy = d.explanation.front();
  CHECK(healthy.effect == sim::EffectKind::kMotionNoiseFloor);
  CHECK_FALSE(healthy.negligible);
  CHECK(healthy.size_pieces == "spot turn");
  CHECK(healthy.relative_size > 0.5);
  CHECK_THAT(healthy.size_mrad, WithinRel(1e3 * std::sqrt(2.0) * 0.002 / b, 0.15));
  const nlohmann::json j = DiagnoseToJson(d);
  CHECK(j.at("explanation").at(0).at("size_pieces") == "spot turn");

  s.sim.effects.floor_sigma = 0.0002;
  const CampaignData tiny = Build(s);
  DiagnoseOptions all = Fast();
  all.negligible = 0.0;  // significant, on little evidence (under 2 nats given nothing else)
  d = Diagnose(tiny, all);
  INFO(d.verdict_reason);
  // Every size counts, but the evidence is not decisive: a step, not named,
  // and a gap closed so is not `none` either.
  CHECK(d.verdict == "unexplained");
  REQUIRE_FALSE(d.explanation.empty());
  CHECK(d.explanation.front().not_decisive);
  CHECK(d.explanation.front().earned_given_others_nats < std::log(100.0));
  all.decisive_nats = 0.0;  // named when every size and every gain counts
  d = Diagnose(tiny, all);
  CHECK(d.verdict == "motion_noise_floor");
  d = Diagnose(tiny, Fast());
  CHECK(d.verdict == "none");
  REQUIRE_FALSE(d.explanation.empty());
  CHECK(d.explanation.front().effect == sim::EffectKind::kMotionNoiseFloor);
  CHECK(d.explanation.front().negligible);
  CHECK(d.explanation.front().relative_size < 0.25);
  CHECK(d.explanation.front().size_mrad < 1e3 * std::sqrt(2.0) * 0.001 / b);
}

TEST_CASE("endpoint data check: single runs, copies, all zero", "[diagnose][warnings]") {
  auto run = [](const char* dir, double ex, double ey, std::optional<double> th) {
    ReturnError r;
    r.run = "r";
    r.direction = dir;
    r.ex_m = ex;
    r.ey_m = ey;
    r.etheta_rad = th;
    return r;
  };
  EndpointDataCheck ok;
  for (int i = 0; i < 5; ++i) {
    ok.Add(run("cw", 0.01 + 1e-3 * i, -0.02, 0.01));
    ok.Add(run("ccw", -0.01, 0.02 + 1e-3 * i, std::nullopt));
  }
  CHECK(ok.Warnings("sq.csv").empty());
  EndpointDataCheck copies;
  for (int i = 0; i < 5; ++i) copies.Add(run(i % 2 ? "cw" : "ccw", 0.012, -0.004, 0.02));
  auto w = copies.Warnings("sq.csv");
  REQUIRE(w.size() == 1);
  CHECK(w[0] == "sq.csv: all 5 runs end at exactly the same return error (zero scatter): real runs scatter, so check "
                "the runs are not copies");
  EndpointDataCheck zero;
  for (int i = 0; i < 4; ++i) zero.Add(run(i % 2 ? "cw" : "ccw", 0.0, 0.0, std::nullopt));
  w = zero.Warnings("sq.csv");
  REQUIRE(w.size() == 1);
  CHECK(w[0].find("every return error is exactly 0 (4 runs)") != std::string::npos);
  EndpointDataCheck single;
  single.Add(run("cw", 0.01, 0.0, 0.0));
  w = single.Warnings("one.csv");
  REQUIRE(w.size() == 1);
  CHECK(w[0].find("one.csv: a single run") == 0);
}

TEST_CASE("umbmark diagnose: degenerate endpoint files are warned about in the JSON", "[diagnose][cli][warnings]") {
  using testing::Q;
  const auto dir = testing::TempDir("diagnose-endpoint-warn");
  Small s = MakeSmall(83, 1, 10);  // one cw and one ccw square, as return errors
  s.sim.endpoint_squares = true;
  const sim::SimulatedCampaign c = sim::SimulateCampaign(s.manifest, s.sim);
  const std::string manifest = io::WriteCampaign(c.manifest, c.data, (dir / "campaign").string());
  const auto r = testing::RunCli("diagnose " + Q(manifest) + " --null-sims 20 --folds 2 --json -");
  INFO(r.err);
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(r.out);
  REQUIRE(j.contains("warnings"));
  int single = 0;
  for (const auto& w : j["warnings"])
    single += w.get<std::string>().find("only 1 cw run") != std::string::npos ||
              w.get<std::string>().find("only 1 ccw run") != std::string::npos;
  CHECK(single == 2);
  CHECK(r.err.find("warning: ") != std::string::npos);
}

TEST_CASE("diagnose: the next steps say how many more squares would determine a correction the runs do not",
          "[diagnose][advice]") {
  // plan --check's analysis (planning/advice.hpp) on the campaign: a 0.03 %
  // diameter-ratio error is far inside what 5 + 5 noisy squares determine
  // (their E_d half-width is of the order of 1e-3), a 1.2 % wheelbase error
  // far outside it. So the next steps carry calibrate's record-more sentence
  // for E_d and none for E_b.
  Small s = MakeSmall(81);
  s.sim.truth.E_d = 1.0003;
  const DiagnoseSummary d = Diagnose(Build(s), Fast());
  INFO("baseline E_d " << d.baseline.E_d << ", E_b " << d.baseline.E_b);
  const auto said = [&](const std::string& head) {
    return std::any_of(d.next_steps.begin(), d.next_steps.end(),
                       [&](const std::string& t) { return t.rfind(head, 0) == 0; });
  };
  CHECK(said("E_d's correction"));
  CHECK_FALSE(said("E_b's correction"));
}
