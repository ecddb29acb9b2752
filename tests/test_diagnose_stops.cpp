// The diagnosis' two readings of the contract's stop (diagnosis/stop_model.hpp):
// the body reading's rest-phase moments against a Monte Carlo of the
// contract's controller (stop when the odometry reaches the target), the
// body campaign's travel shifts and count covariances to the closed form,
// and the reading the likelihood picks on our own simulator's campaigns,
// whose controller stops each wheel on its tick.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "diagnosis/diagnose.hpp"
#include "diagnosis/pieces.hpp"
#include "diagnosis/stop_model.hpp"
#include "support/diag_campaign.hpp"

using namespace umbmark;
using namespace umbmark::diag;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

/// Rest phases (tick units, from the edge of the wheel's last count) of a
/// controller that stops a straight leg when its odometry, the mean of the
/// two counts, reaches `target` counts: both wheels turn at the same speed
/// from independent uniform start phases; the controller reacts at the
/// count that completes the target (event by event, no control period).
/// The target is a length, so its fraction of a count is arbitrary: drawn
/// uniformly (with whole-count targets and equal speeds the other wheel's
/// rest would follow the start phases' difference instead).
std::pair<double, double> ContractStop(std::mt19937_64& g, double target) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  // Position p of each wheel in ticks; the count is floor(p).
  double pl = u(g), pr = u(g);
  const double cl0 = std::floor(pl), cr0 = std::floor(pr);
  for (;;) {
    // The next count: the wheel nearest to its next edge.
    const double to_l = std::floor(pl) + 1.0 - pl, to_r = std::floor(pr) + 1.0 - pr;
    const double step = std::min(to_l, to_r);
    pl += step;
    pr += step;
    // Land exactly on the edge of the wheel that counted.
    if (to_l <= to_r) pl = std::round(pl);
    if (to_r <= to_l) pr = std::round(pr);
    const double odometry = 0.5 * ((std::floor(pl) - cl0) + (std::floor(pr) - cr0));
    if (odometry >= target) return {pl - std::floor(pl), pr - std::floor(pr)};
  }
}

}  // namespace

TEST_CASE("stop model: body reading's rest phases match a Monte Carlo of the contract's controller", "[diagnose][stops]") {
  // 40000 stops: the moments' standard errors are < 0.002; tolerance 0.006.
  std::mt19937_64 g(20261124);
  std::uniform_real_distribution<double> target(5.0, 50.0);
  const int n = 40000;
  double sl = 0, sr = 0, sll = 0, srr = 0, slr = 0;
  for (int i = 0; i < n; ++i) {
    const auto [ul, ur] = ContractStop(g, target(g));
    sl += ul;
    sr += ur;
    sll += ul * ul;
    srr += ur * ur;
    slr += ul * ur;
  }
  const double ml = sl / n, mr = sr / n;
  CHECK_THAT(ml, WithinAbs(BodyStopMoments::kMean, 0.006));
  CHECK_THAT(mr, WithinAbs(BodyStopMoments::kMean, 0.006));
  CHECK_THAT(sll / n - ml * ml, WithinAbs(BodyStopMoments::kVar, 0.006));
  CHECK_THAT(srr / n - mr * mr, WithinAbs(BodyStopMoments::kVar, 0.006));
  CHECK_THAT(slr / n - ml * mr, WithinAbs(BodyStopMoments::kCov, 0.006));
  // The tick-exact reading (u = 0 for both wheels) is far off: the mean
  // rest phase is 1/4 tick, not 0.
  CHECK(ml > 0.2);

  // DrawBodyStop (the null distribution's draws) has the same moments: zero
  // mean error, var 5/48 t^2, cov -s_L s_R t_L t_R / 16.
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double tl = 2e-3, tr = 3e-3;
  double el = 0, er = 0, ell = 0, err = 0, elr = 0;
  for (int i = 0; i < n; ++i) {
    const auto [a, b] = DrawBodyStop(u(g), u(g), -1, +1, tl, tr);  // a spot turn: left backward
    el += a;
    er += b;
    ell += a * a;
    err += b * b;
    elr += a * b;
  }
  CHECK_THAT(el / n / tl, WithinAbs(0.0, 0.006));
  CHECK_THAT(er / n / tr, WithinAbs(0.0, 0.006));
  CHECK_THAT(ell / n / (tl * tl), WithinAbs(5.0 / 48.0, 0.006));
  CHECK_THAT(err / n / (tr * tr), WithinAbs(5.0 / 48.0, 0.006));
  CHECK_THAT(elr / n / (tl * tr), WithinAbs(+1.0 / 16.0, 0.006));
}

TEST_CASE("stop model: the body campaign moves joint stops by s t / 4 with the closed-form covariance", "[diagnose][stops]") {
  testing::SmallCampaign s = testing::MakeSmallCampaign(5, 2, 2);
  s.manifest.robot.ticks_per_rev = 1024;
  const CampaignData edge = testing::BuildSmallCampaign(s);
  REQUIRE(HasJointStops(edge));
  const CampaignData body = WithBodyStops(edge);
  CHECK(body.stop_model == StopModel::kBody);
  const double tl = edge.tick_left_m, tr = edge.tick_right_m;
  REQUIRE_THAT(tl, WithinRel(M_PI * 0.1 / 1024, 1e-12));
  int joint = 0, turns = 0;
  for (std::size_t k = 0; k < edge.runs.size(); ++k) {
    const DiagRun& a = edge.runs[k];
    const DiagRun& b = body.runs[k];
    for (std::size_t i = 0; i < a.t.size(); ++i) {
      const int sl = a.stop_dir_left[i], sr = a.stop_dir_right[i];
      if (sl == 0 || sr == 0) {
        CHECK(b.left[i] == a.left[i]);
        CHECK(b.q_cov_lr[i] == 0.0);
        continue;
      }
      ++joint;
      turns += sl != sr;
      CHECK(a.q_sd_left[i] == 0.0);  // tick-exact: no count error after a stop
      CHECK_THAT(b.left[i] - a.left[i], WithinAbs(sl * tl / 4.0, 1e-12));
      CHECK_THAT(b.right[i] - a.right[i], WithinAbs(sr * tr / 4.0, 1e-12));
      CHECK_THAT(b.q_sd_left[i], WithinRel(tl * std::sqrt(5.0 / 48.0), 1e-12));
      CHECK_THAT(b.q_cov_lr[i], WithinRel(-sl * sr * tl * tr / 16.0, 1e-12));
    }
  }
  // 4 squares (4 legs + 4 turns) and 2 back-and-forth runs (2 legs), the
  // stops held through their pauses: many joint-stop samples, some after turns.
  CHECK(joint > 20);
  CHECK(turns > 4);
}

TEST_CASE("stop model: on our own simulator (each wheel stopped on its tick) the tick-exact reading wins", "[diagnose][stops]") {
  // 1024 ticks/rev (0.31 mm per tick): the readings differ by far more than
  // the noise; the clean campaign stays `none`.
  testing::SmallCampaign s = testing::MakeSmallCampaign(17, 5, 10);
  s.manifest.robot.ticks_per_rev = 1024;
  DiagnoseOptions o;
  o.null_simulations = 100;
  o.seed = 3;
  const DiagnoseSummary d = Diagnose(testing::BuildSmallCampaign(s), o);
  CHECK(d.stop_model == StopModel::kWheelEdge);
  CHECK(d.verdict == "none");
}
