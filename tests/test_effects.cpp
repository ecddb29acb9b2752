// Signature tests of the campaign simulator's effects (contract, "Effects"):
// every effect produces exactly the footprint its definition implies, checked
// against closed forms on noise-free runs (wheel travel logged as distance, so
// no quantisation) or, for the noise effects, against Monte Carlo moments.
#include <catch2/catch.hpp>

#include <cmath>
#include <variant>

#include "core/angles.hpp"
#include "simulation/campaign_sim.hpp"
#include "simulation/effects.hpp"
#include "simulation/effects_motion.hpp"
#include "support/effect_campaign.hpp"

using namespace umbmark;
using namespace umbmark::sim;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

constexpr double kB = 0.4;     // nominal wheelbase [m]
constexpr double kSide = 2.0;  // square side [m]
constexpr double kDist = 2.0;  // back-and-forth distance [m]

RobotParams Robot(bool ticks) {
  RobotParams r;
  r.wheelbase_m = kB;
  r.wheel_diameter_left_m = 0.1;
  r.wheel_diameter_right_m = 0.1;
  if (ticks) r.ticks_per_rev = 4096;
  return r;
}

Manifest Campaign(bool ticks, bool square = true, bool back_and_forth = true) {
  Manifest m = StandardCampaignManifest(Robot(ticks), kSide, kDist, GroundTruthNoise{0.0, 0.0});
  std::vector<Experiment> keep;
  for (const auto& e : m.experiments)
    if ((e.kind == ExperimentKind::kSquare && square) || (e.kind == ExperimentKind::kBackAndForth && back_and_forth))
      keep.push_back(e);
  m.experiments = keep;
  return m;
}

const TrajectoryData& Traj(const SimulatedCampaign& c, std::size_t e) { return std::get<TrajectoryData>(c.data[e]); }

Pose2 Last(const TrajectoryRun& r) { return r.GroundTruth(r.size() - 1); }

/// Ground truth at the sample nearest to time t.
Pose2 At(const TrajectoryRun& r, double t) {
  std::size_t best = 0;
  for (std::size_t i = 0; i < r.size(); ++i)
    if (std::abs(r.t_s[i] - t) < std::abs(r.t_s[best] - t)) best = i;
  return r.GroundTruth(best);
}

double MaxX(const TrajectoryRun& r) {
  double m = -1e9;
  for (double x : r.gt_x_m) m = std::max(m, x);
  return m;
}

/// Time in the middle of the pause after the forward leg of back-and-forth.
double FarPauseTime(const CampaignSimOptions& o) { return o.pause_s + kDist / o.speed_m_s + 0.5 * o.pause_s; }

double Variance(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m += x;
  m /= static_cast<double>(v.size());
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return s / static_cast<double>(v.size() - 1);
}

}  // namespace

TEST_CASE("effects: spec parsing round-trips and rejects bad specs", "[effects]") {
  Effects fx;
  ParseEffectSpec("gt_offset:dx=0.02,dy=-0.01", fx);
  ParseEffectSpec("turn_scrub:k=0.05", fx);
  CHECK(fx.gt_dx == 0.02);
  CHECK(fx.gt_dy == -0.01);
  CHECK(fx.scrub_k == 0.05);
  CHECK(fx.ActiveKinds() == std::vector<EffectKind>{EffectKind::kTurnScrub, EffectKind::kGtOffset});
  Effects back;
  ParseEffectSpec(EffectSpecString(EffectKind::kGtOffset, fx), back);
  CHECK(back.gt_dx == fx.gt_dx);
  CHECK(back.gt_dy == fx.gt_dy);
  CHECK_THROWS_AS(ParseEffectSpec("warp_drive:x=1", fx), InvalidOptions);
  CHECK_THROWS_AS(ParseEffectSpec("turn_scrub", fx), InvalidOptions);
  CHECK_THROWS_AS(ParseEffectSpec("turn_scrub:q=1", fx), InvalidOptions);
  CHECK_THROWS_AS(ParseEffectSpec("turn_scrub:k=abc", fx), InvalidOptions);
  CHECK_THROWS_AS(ParseEffectSpec("turn_scrub:k=1,k=2", fx), InvalidOptions);
  CHECK_THROWS_AS(ParseEffectSpec("turn_scrub:k=nan", fx), InvalidOptions);
  Effects bad;
  bad.noise_rho = 1.5;
  CHECK_THAT(bad.Check(), Catch::Contains("correlated_noise.rho"));
  CHECK(ContractEffects().size() == 14);  // the nine, standstill_motion, motion_noise_floor, run_time_offset, stop_slide, castor_swivel
}

TEST_CASE("simulate: nominal robot, no noise: ground truth follows the commanded path", "[effects]") {
  const CampaignSimOptions o = testing::QuietOptions(2, 2);
  const SimulatedCampaign c = SimulateCampaign(Campaign(false), o);
  for (const auto& run : Traj(c, 0).runs) {
    const Pose2 end = Last(run);
    CHECK_THAT(end.x, WithinAbs(0.0, 1e-9));
    CHECK_THAT(end.y, WithinAbs(0.0, 1e-9));
    CHECK_THAT(std::abs(end.theta), WithinAbs(2.0 * kPi, 1e-9));
    // Corner after the first leg (ccw turns left, cw right): (side, 0).
    const Pose2 corner = At(run, o.pause_s + kSide / o.speed_m_s + 0.5 * o.pause_s);
    CHECK_THAT(corner.x, WithinAbs(kSide, 1e-9));
    CHECK_THAT(corner.y, WithinAbs(0.0, 1e-9));
  }
  for (const auto& run : Traj(c, 1).runs) CHECK_THAT(MaxX(run), WithinAbs(kDist, 1e-9));
}

TEST_CASE("simulate: true robot is c_L D_L, c_R D_R, E_b b (contract's E_d, E_b)", "[effects]") {
  const double E_d = 1.003, E_b = 1.015;
  CampaignSimOptions o = testing::QuietOptions(2, 2);
  o.truth.E_d = E_d;
  o.truth.E_b = E_b;
  const SimulatedCampaign c = SimulateCampaign(Campaign(false), o);
  const double c_L = 2.0 / (E_d + 1.0), c_R = 2.0 / (1.0 / E_d + 1.0);  // B&F eqs. 4.31, 4.32
  // Forward leg of back-and-forth: one exact arc with wheel travels c D.
  const double l = c_L * kDist, r = c_R * kDist, b = E_b * kB;
  const double dtheta = (r - l) / b, ds = 0.5 * (l + r);
  for (const auto& run : Traj(c, 1).runs) {
    const Pose2 far = At(run, FarPauseTime(o));
    CHECK_THAT(far.theta, WithinAbs(dtheta, 1e-12));
    CHECK_THAT(far.x, WithinAbs(ds / dtheta * std::sin(dtheta), 1e-9));
    CHECK_THAT(far.y, WithinAbs(ds / dtheta * (1.0 - std::cos(dtheta)), 1e-9));
    // The backward leg retraces the same circle: back at the start.
    CHECK_THAT(Last(run).x, WithinAbs(0.0, 1e-9));
    CHECK_THAT(Last(run).theta, WithinAbs(0.0, 1e-12));
  }
  // A commanded 90 deg spot turn turns (c_L + c_R) / (2 E_b) times 90 deg.
  for (const auto& run : Traj(c, 0).runs) {
    const double sign = run.direction == "cw" ? -1.0 : 1.0;
    const Pose2 corner = At(run, o.pause_s + kSide / o.speed_m_s + o.pause_s + (kPi / 2.0) / o.turn_rate_rad_s +
                                     0.5 * o.pause_s);
    const double leg = (c_R - c_L) * kSide / b;
    CHECK_THAT(corner.theta, WithinAbs(leg + sign * (kPi / 2.0) * (c_L + c_R) / (2.0 * E_b), 1e-12));
  }
}

TEST_CASE("scale_error: legs are (1 + s) longer, back-and-forth returns to the start", "[effects]") {
  CampaignSimOptions o = testing::QuietOptions(2, 2);
  o.effects.scale_s = 0.02;
  const SimulatedCampaign c = SimulateCampaign(Campaign(false), o);
  for (const auto& run : Traj(c, 1).runs) {
    CHECK_THAT(MaxX(run), WithinAbs(1.02 * kDist, 1e-9));
    CHECK_THAT(Last(run).x, WithinAbs(0.0, 1e-9));
  }
  for (const auto& run : Traj(c, 0).runs) {
    const Pose2 corner = At(run, o.pause_s + kSide / o.speed_m_s + 0.5 * o.pause_s);
    CHECK_THAT(corner.x, WithinAbs(1.02 * kSide, 1e-9));
    // Turns over-rotate by the same factor (the wheels roll 2% further).
    const double sign = run.direction == "cw" ? -1.0 : 1.0;
    CHECK_THAT(Last(run).theta, WithinAbs(sign * 2.0 * kPi * 1.02, 1e-9));
  }
}

TEST_CASE("turn_scrub: CW and CCW shift alike (as a wheelbase error), straight runs untouched", "[effects]") {
  const double k = 0.04;
  CampaignSimOptions scrub = testing::QuietOptions(2, 2);
  scrub.effects.scrub_k = k;
  CampaignSimOptions wheelbase = testing::QuietOptions(2, 2);
  wheelbase.truth.E_b = 1.0 / (1.0 - k);
  CampaignSimOptions plain = testing::QuietOptions(2, 2);
  // Distance mode: with encoder ticks the legs' one-tick wheel differences
  // would turn by a slightly different amount under the two wheelbases.
  const SimulatedCampaign a = SimulateCampaign(Campaign(false), scrub);
  const SimulatedCampaign b = SimulateCampaign(Campaign(false), wheelbase);
  const SimulatedCampaign p = SimulateCampaign(Campaign(false), plain);
  for (std::size_t r = 0; r < Traj(a, 0).runs.size(); ++r) {
    const Pose2 ea = Last(Traj(a, 0).runs[r]), eb = Last(Traj(b, 0).runs[r]);
    CHECK_THAT(ea.x, WithinAbs(eb.x, 1e-9));
    CHECK_THAT(ea.y, WithinAbs(eb.y, 1e-9));
    CHECK_THAT(ea.theta, WithinAbs(eb.theta, 1e-9));
    // Each 90 deg turn is k short: the final heading misses 2 pi by 2 pi k.
    const double sign = Traj(a, 0).runs[r].direction == "cw" ? -1.0 : 1.0;
    CHECK_THAT(ea.theta, WithinAbs(sign * 2.0 * kPi * (1.0 - k), 1e-12));
  }
  // Back-and-forth has no spot turn: identical to the robot without the effect.
  for (std::size_t r = 0; r < Traj(a, 1).runs.size(); ++r) {
    const auto& ra = Traj(a, 1).runs[r];
    const auto& rp = Traj(p, 1).runs[r];
    REQUIRE(ra.size() == rp.size());
    for (std::size_t i = 0; i < ra.size(); ++i) {
      CHECK(ra.gt_x_m[i] == rp.gt_x_m[i]);
      CHECK(ra.gt_theta_rad[i] == rp.gt_theta_rad[i]);
    }
  }
}

TEST_CASE("direction_asymmetry: backward travel is (1 + a) longer", "[effects]") {
  const double a = 0.03;
  CampaignSimOptions o = testing::QuietOptions(2, 2);
  o.effects.asymmetry_a = a;
  const SimulatedCampaign c = SimulateCampaign(Campaign(false), o);
  for (const auto& run : Traj(c, 1).runs) {
    CHECK_THAT(MaxX(run), WithinAbs(kDist, 1e-9));        // forward leg unaffected
    CHECK_THAT(Last(run).x, WithinAbs(-a * kDist, 1e-9));  // backward leg (1 + a) D
    CHECK_THAT(Last(run).y, WithinAbs(0.0, 1e-9));
  }
  // In a spot turn the inner wheel turns backwards: each turn over-rotates by
  // a/2 of its angle, and the axle centre moves backwards by a b phi / 4.
  for (const auto& run : Traj(c, 0).runs) {
    const double sign = run.direction == "cw" ? -1.0 : 1.0;
    CHECK_THAT(Last(run).theta, WithinAbs(sign * 2.0 * kPi * (1.0 + a / 2.0), 1e-9));
    const Pose2 corner = At(run, o.pause_s + kSide / o.speed_m_s + o.pause_s + (kPi / 2.0) / o.turn_rate_rad_s +
                                     0.5 * o.pause_s);
    const double phi = kPi / 2.0 * (1.0 + a / 2.0);
    const double ds = -a * kB * (kPi / 2.0) / 4.0;  // (l + r)/2
    // Exact arc: chord ds sinc(phi/2) along phi/2.
    CHECK_THAT(corner.x, WithinAbs(kSide + ds * std::sin(phi / 2.0) / (phi / 2.0) * std::cos(phi / 2.0), 1e-9));
    CHECK_THAT(corner.y, WithinAbs(sign * ds * std::sin(phi / 2.0) / (phi / 2.0) * std::sin(phi / 2.0), 1e-9));
  }
}

TEST_CASE("castor_kick: heading jumps at every start from standstill, not at spot turns", "[effects]") {
  const double kappa = 0.01;
  CampaignSimOptions o = testing::QuietOptions(2, 2);
  o.effects.castor_kappa = kappa;
  const SimulatedCampaign c = SimulateCampaign(Campaign(false), o);
  for (const auto& run : Traj(c, 1).runs) {
    // Forward at heading kappa, then the backward start kicks -kappa.
    const Pose2 end = Last(run);
    CHECK_THAT(end.x, WithinAbs(kDist * (std::cos(kappa) - 1.0), 1e-9));
    CHECK_THAT(end.y, WithinAbs(kDist * std::sin(kappa), 1e-9));
    CHECK_THAT(end.theta, WithinAbs(0.0, 1e-12));
  }
  for (const auto& run : Traj(c, 0).runs) {
    // Four legs, four kicks of +kappa, CW and CCW alike.
    const double sign = run.direction == "cw" ? -1.0 : 1.0;
    CHECK_THAT(Last(run).theta, WithinAbs(sign * 2.0 * kPi + 4.0 * kappa, 1e-9));
  }
}

TEST_CASE("parameter_drift: the right diameter grows by r per run, across experiments", "[effects]") {
  const double r = 2e-4;
  CampaignSimOptions o = testing::QuietOptions(3, 3);
  o.effects.drift_r = r;
  const SimulatedCampaign c = SimulateCampaign(Campaign(false), o);
  // Back-and-forth is experiment 2: its runs are campaign runs 6, 7, 8.
  const auto& runs = Traj(c, 1).runs;
  for (std::size_t j = 0; j < runs.size(); ++j) {
    const double i = 6.0 + static_cast<double>(j);
    // Forward leg: right wheel rolls (1 + r i) D, left D: heading D r i / b.
    const Pose2 far = At(runs[j], FarPauseTime(o));
    CHECK_THAT(far.theta, WithinAbs(kDist * r * i / kB, 1e-9));
  }
}

TEST_CASE("gt_offset: ground truth reports a point of the robot frame", "[effects]") {
  const double dx = 0.03, dy = -0.02;
  CampaignSimOptions o = testing::QuietOptions(2, 2);
  o.effects.gt_dx = dx;
  o.effects.gt_dy = dy;
  const SimulatedCampaign c = SimulateCampaign(Campaign(false, true, false), o);
  for (const auto& run : Traj(c, 0).runs) {
    const Pose2 start = run.GroundTruth(0);
    CHECK_THAT(start.x, WithinAbs(dx, 1e-12));
    CHECK_THAT(start.y, WithinAbs(dy, 1e-12));
    // After leg 1 and turn 1 the robot stands at (side, 0) facing +-90 deg.
    const double th = run.direction == "cw" ? -kPi / 2.0 : kPi / 2.0;
    const Pose2 corner = At(run, o.pause_s + kSide / o.speed_m_s + o.pause_s + (kPi / 2.0) / o.turn_rate_rad_s +
                                     0.5 * o.pause_s);
    CHECK_THAT(corner.x, WithinAbs(kSide + std::cos(th) * dx - std::sin(th) * dy, 1e-9));
    CHECK_THAT(corner.y, WithinAbs(std::sin(th) * dx + std::cos(th) * dy, 1e-9));
  }
}

TEST_CASE("time_offset: a sample stamped t shows the pose at t - tau", "[effects]") {
  CampaignSimOptions o = testing::QuietOptions(2, 2);
  o.effects.time_tau = 0.1;  // two samples at 20 Hz
  const SimulatedCampaign c = SimulateCampaign(Campaign(false), o);
  const SimulatedCampaign ref = SimulateCampaign(Campaign(false), testing::QuietOptions(2, 2));
  for (std::size_t e = 0; e < 2; ++e) {
    const auto& run = Traj(c, e).runs[0];
    const auto& base = Traj(ref, e).runs[0];
    REQUIRE(run.size() == base.size());
    for (std::size_t i = 0; i < run.size(); ++i) {
      const std::size_t j = i >= 2 ? i - 2 : 0;
      CHECK_THAT(run.gt_x_m[i], WithinAbs(base.gt_x_m[j], 1e-9));
      CHECK_THAT(run.gt_y_m[i], WithinAbs(base.gt_y_m[j], 1e-9));
      CHECK_THAT(run.gt_theta_rad[i], WithinAbs(base.gt_theta_rad[j], 1e-9));
    }
  }
}

TEST_CASE("bump_outliers: Poisson count per metre, N(0, sigma^2) per bump", "[effects]") {
  CampaignSimOptions o = testing::QuietOptions(400, 400);
  o.effects.bump_rate = 0.5;
  o.effects.bump_sigma = 0.004;
  o.seed = 7;
  Manifest m = Campaign(false, false, true);
  m.experiments[0].distance_m = 1.0;
  const SimulatedCampaign c = SimulateCampaign(m, o);
  double bumps = 0.0;
  for (int b : c.bumps[0]) bumps += b;
  // Each run rolls 2 m per wheel: expected 2 wheels * 2 m * rate bumps.
  const double expected = 400.0 * 2.0 * 2.0 * 0.5;
  CHECK(std::abs(bumps - expected) < 4.0 * std::sqrt(expected));
  // Along-track return error: each bump moves the axle centre by half its
  // size: Var(x) = E[N] sigma^2 / 4 per run (to first order).
  std::vector<double> x;
  for (const auto& run : Traj(c, 0).runs) x.push_back(Last(run).x);
  const double predicted = 2.0 * 2.0 * 0.5 * 0.004 * 0.004 / 4.0;
  CHECK_THAT(Variance(x), WithinRel(predicted, 0.35));  // relative SE ~0.09
}

TEST_CASE("correlated_noise: along-track and heading variances follow rho", "[effects]") {
  // Straight 1 m legs: Var(along) = (k_L^2 + k_R^2 + 2 rho k_L k_R) D / 4,
  // Var(heading) = (k_L^2 + k_R^2 - 2 rho k_L k_R) D / b^2 (eq. 4 with
  // correlated wheel errors). 300 runs: sample variances within ~25 %.
  for (double rho : {0.8, -0.6}) {
    CampaignSimOptions o = testing::QuietOptions(300, 300);
    o.truth.k_L = 0.004;
    o.truth.k_R = 0.006;
    o.effects.noise_rho = rho;
    o.seed = 11;
    Manifest m = Campaign(false, false, true);
    m.experiments[0].distance_m = 1.0;
    const SimulatedCampaign c = SimulateCampaign(m, o);
    std::vector<double> along, heading;
    const double t_far = o.pause_s + 1.0 / o.speed_m_s + 0.5 * o.pause_s;
    for (const auto& run : Traj(c, 0).runs) {
      const Pose2 far = At(run, t_far);
      along.push_back(far.x);
      heading.push_back(far.theta);
    }
    const double kl = 0.004, kr = 0.006;
    const double var_along = (kl * kl + kr * kr + 2.0 * rho * kl * kr) / 4.0;
    const double var_heading = (kl * kl + kr * kr - 2.0 * rho * kl * kr) / (kB * kB);
    CHECK_THAT(Variance(along), WithinRel(var_along, 0.25));
    CHECK_THAT(Variance(heading), WithinRel(var_heading, 0.25));
  }
}

TEST_CASE("outside effects: gt_yaw_misalignment and floor_slope", "[effects]") {
  CampaignSimOptions o = testing::QuietOptions(2, 2);
  o.effects.yaw_delta = 0.02;
  o.effects.slope_g = 0.01;
  o.effects.slope_dir = kPi / 2.0;  // slides towards +y of the start frame
  const SimulatedCampaign c = SimulateCampaign(Campaign(false, false, true), o);
  for (const auto& run : Traj(c, 0).runs) {
    CHECK_THAT(run.GroundTruth(0).theta, WithinAbs(0.02, 1e-12));
    // 2 D of travel, g per metre, towards +y.
    CHECK_THAT(Last(run).y, WithinAbs(0.01 * 2.0 * kDist, 1e-9));
    CHECK_THAT(Last(run).x, WithinAbs(0.0, 1e-9));
  }
}

TEST_CASE("motion segmentation: back-to-back legs, turns and reversals are separate motions", "[effects]") {
  // 10 intervals forward, 5 of a ccw spot turn, 10 backward, no pause; then
  // an arc in which the left wheel pauses for one interval (still one motion).
  std::vector<double> L{0.0}, R{0.0};
  auto step = [&](double dl, double dr, int n) {
    for (int i = 0; i < n; ++i) {
      L.push_back(L.back() + dl);
      R.push_back(R.back() + dr);
    }
  };
  step(0.01, 0.01, 10);
  step(-0.005, 0.005, 5);
  step(-0.01, -0.01, 10);
  step(0.0, 0.0, 3);
  step(0.01, 0.02, 4);
  step(0.0, 0.02, 1);
  step(0.01, 0.02, 4);
  const auto m = SegmentMotions(L, R, 0.3);
  REQUIRE(m.size() == 4);
  CHECK(m[0].first_interval == 0);
  CHECK(m[0].last_interval == 9);
  CHECK(m[0].cls == MotionClass::kStraight);
  CHECK(m[0].sign == 1);
  CHECK(m[1].first_interval == 10);
  CHECK(m[1].last_interval == 14);
  CHECK(m[1].cls == MotionClass::kTurn);
  CHECK(m[1].sign == 1);
  CHECK(m[2].first_interval == 15);
  CHECK(m[2].last_interval == 24);
  CHECK(m[2].cls == MotionClass::kStraight);
  CHECK(m[2].sign == -1);
  CHECK(m[3].first_interval == 28);
  CHECK(m[3].last_interval == 36);
  CHECK(m[3].cls == MotionClass::kArc);
}

TEST_CASE("simulate: encoder ticks are whole counts of true rotation; controller stops on the target", "[effects]") {
  CampaignSimOptions o = testing::QuietOptions(2, 2);
  o.truth.E_d = 1.01;  // true diameters differ from nominal: counts are the nominal ones
  const SimulatedCampaign c = SimulateCampaign(Campaign(true, false, true), o);
  const RobotParams robot = Robot(true);
  const double target = std::round(kDist / robot.MetresPerTickLeft());
  for (const auto& run : Traj(c, 0).runs) {
    // Back at the start count after forward D and backward D.
    CHECK(std::abs(run.ticks_left.back() - run.ticks_left.front()) <= 1);
    std::int64_t max_left = 0;
    for (auto t : run.ticks_left) max_left = std::max(max_left, t);
    CHECK(static_cast<double>(max_left) == target);
  }
}

TEST_CASE("castor_kick: no kick between motions back to back (no standstill), one at the run's start", "[effects]") {
  // The contract: "at every start from standstill". Without pauses only the
  // run's first motion starts from standstill; a leg right after a spot
  // turn, or a reversal without a pause, does not.
  const double kappa = 0.01;
  CampaignSimOptions o = testing::QuietOptions(2, 2);
  o.effects.castor_kappa = kappa;
  o.pause_s = 0.0;
  const SimulatedCampaign c = SimulateCampaign(Campaign(false), o);
  for (const auto& run : Traj(c, 1).runs) {
    // One kick of +kappa forward, none at the reversal: the backward leg
    // retraces the forward one at heading kappa and ends at the start.
    const Pose2 end = Last(run);
    CHECK_THAT(end.x, WithinAbs(0.0, 1e-9));
    CHECK_THAT(end.y, WithinAbs(0.0, 1e-9));
    CHECK_THAT(end.theta, WithinAbs(kappa, 1e-12));
  }
  for (const auto& run : Traj(c, 0).runs) {
    const double sign = run.direction == "cw" ? -1.0 : 1.0;
    CHECK_THAT(Last(run).theta, WithinAbs(sign * 2.0 * kPi + kappa, 1e-9));
  }
}

TEST_CASE("standstill_motion: the pose moves only between a motion's end and the next start", "[effects]") {
  // Noise-free robot: every ground-truth change while the encoders are still
  // is the settling, drawn once per standstill (constant over it), with the
  // stated spread over many standstills.
  CampaignSimOptions o = testing::QuietOptions(20, 20);
  o.effects.stand_sigma_xy = 0.004;
  o.effects.stand_sigma_theta = 0.003;
  const SimulatedCampaign c = SimulateCampaign(Campaign(true), o);
  std::vector<double> dxy, dth;
  for (const auto& run : Traj(c, 1).runs) {
    for (std::size_t j = 1; j + 1 < run.size(); ++j) {
      const bool still_before = run.ticks_left[j] == run.ticks_left[j - 1] && run.ticks_right[j] == run.ticks_right[j - 1];
      const bool still_after = run.ticks_left[j + 1] == run.ticks_left[j] && run.ticks_right[j + 1] == run.ticks_right[j];
      if (still_before && still_after) {
        // Inside a standstill the pose does not move.
        CHECK_THAT(run.gt_x_m[j + 1] - run.gt_x_m[j], WithinAbs(0.0, 1e-12));
        CHECK_THAT(run.gt_theta_rad[j + 1] - run.gt_theta_rad[j], WithinAbs(0.0, 1e-12));
      }
    }
    // The back-and-forth's far standstill: the robot-frame displacement
    // beyond the commanded leg is the settling.
    const Pose2 far = At(run, FarPauseTime(o));
    dxy.push_back(far.y);
    dth.push_back(far.theta);
  }
  auto sd = [](const std::vector<double>& v) {
    double s = 0.0;
    for (double x : v) s += x * x;
    return std::sqrt(s / static_cast<double>(v.size()));
  };
  // 20 draws: the sample sd within 40 % of sigma.
  CHECK_THAT(sd(dxy), WithinRel(0.004, 0.4));
  CHECK_THAT(sd(dth), WithinRel(0.003, 0.4));
}

TEST_CASE("run_time_offset: each run's ground truth lags by its own tau_i", "[effects]") {
  CampaignSimOptions o = testing::QuietOptions(10, 10);
  o.effects.run_tau_sd = 0.05;
  CampaignSimOptions plain = o;
  plain.effects.run_tau_sd = 0.0;
  const SimulatedCampaign c = SimulateCampaign(Campaign(false), o), c0 = SimulateCampaign(Campaign(false), plain);
  std::vector<double> taus;
  const auto& runs = Traj(c, 1).runs;
  const auto& runs0 = Traj(c0, 1).runs;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    // In the forward leg at constant speed v the lag shows as x(t) = x0(t - tau_i).
    const double v = o.speed_m_s, t_mid = o.pause_s + 0.5 * kDist / v;
    const double lag = (At(runs0[r], t_mid).x - At(runs[r], t_mid).x) / v;
    taus.push_back(lag);
  }
  double m = 0.0, s = 0.0;
  for (double t : taus) m += t;
  m /= static_cast<double>(taus.size());
  for (double t : taus) s += (t - m) * (t - m);
  s = std::sqrt(s / static_cast<double>(taus.size() - 1));
  CHECK(std::abs(m) < 3.0 * 0.05 / std::sqrt(10.0));
  CHECK_THAT(s, WithinRel(0.05, 0.5));
  CHECK(s > 0.0);
}
