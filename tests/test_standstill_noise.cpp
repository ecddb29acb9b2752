// The ground truth's noise inside standstills (diagnosis/standstill_noise.hpp)
// on synthetic runs: 20 Hz samples, standstills of 4 s between one-interval
// motions, the ground truth at rest plus capture noise from a closed-form
// process. Monte Carlo with stated tolerances (about 3 standard errors of
// the robust sd over the ~2000 differences per lag: 1.65 / sqrt(2n) ~ 3 %
// for white noise, more for correlated noise whose differences overlap).
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <vector>

#include "diagnosis/standstill_noise.hpp"

using namespace umbmark::diag;
using umbmark::Pose2;

namespace {

constexpr int kStandstills = 30, kStill = 80;  // samples per standstill: 4 s at 20 Hz

/// One run: standstills of kStill samples joined by one moving interval;
/// `noise(i)` gives the ground truth's error at sample i as (x, y, theta).
template <class Noise>
CampaignData Campaign(Noise noise) {
  CampaignData c;
  DiagRun r;
  const int n = kStandstills * kStill;
  for (int i = 0; i < n; ++i) {
    r.t.push_back(i / 20.0);
    const Pose2 e = noise(i);
    r.gt.push_back(e);
    r.has_gt.push_back(true);
    if (i + 1 < n) r.interval_class.push_back((i + 1) % kStill == 0 ? 0 : -1);
  }
  r.left.assign(r.t.size(), 0.0);
  r.right.assign(r.t.size(), 0.0);
  c.runs.push_back(r);
  return c;
}

}  // namespace

TEST_CASE("standstill noise: white capture noise comes back at lag 1 and at the plateau") {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g(0.0, 1.0);
  const double sxy = 5e-4, sth = 3e-3;
  const CampaignData c = Campaign([&](int) { return Pose2{sxy * g(rng), sxy * g(rng), sth * g(rng)}; });
  const StandstillNoise s = MeasureStandstillNoise(c);
  REQUIRE(s.measured);
  CHECK(s.standstills == kStandstills);
  // Each standstill has 79 still intervals. Left out: 0.5 s (10 samples)
  // after a stop, and the one sample before the next motion. The first
  // standstill follows no stop (78 differences); the last precedes no
  // motion (69); the 28 between have 68.
  CHECK(s.differences == 78 + (kStandstills - 2) * 68 + 69);
  CHECK(s.lag1_sigma_xy_m == Approx(sxy).epsilon(0.08));
  CHECK(s.lag1_sigma_theta_rad == Approx(sth).epsilon(0.1));
  CHECK(s.sigma_xy_m == Approx(sxy).epsilon(0.08));
  CHECK(s.sigma_theta_rad == Approx(sth).epsilon(0.1));
  CHECK(s.plateau_xy);
  CHECK(s.plateau_theta);
  CHECK(s.lag_xy <= 2);
  CHECK_FALSE(s.floored_xy);
}

TEST_CASE("standstill noise: AR(1) capture noise is found at the structure function's plateau") {
  // e_i = r e_{i-1} + sqrt(1 - r^2) sigma w_i: per-sample sd sigma, r(k) = r^k.
  // Lag 1 sees sigma sqrt(1 - r) = 0.447 sigma; the plateau (lag 16:
  // sqrt(1 - 0.8^16) = 0.986) sigma.
  std::mt19937_64 rng(12);
  std::normal_distribution<double> g(0.0, 1.0);
  const double rho = 0.8, sxy = 5e-4, sth = 3e-3, w = std::sqrt(1.0 - rho * rho);
  Pose2 e{sxy * g(rng), sxy * g(rng), sth * g(rng)};
  const CampaignData c = Campaign([&](int) {
    e = Pose2{rho * e.x + w * sxy * g(rng), rho * e.y + w * sxy * g(rng), rho * e.theta + w * sth * g(rng)};
    return e;
  });
  const StandstillNoise s = MeasureStandstillNoise(c);
  REQUIRE(s.measured);
  CHECK(s.lag1_sigma_xy_m == Approx(sxy * std::sqrt(1.0 - rho)).epsilon(0.1));
  CHECK(s.lag1_sigma_theta_rad == Approx(sth * std::sqrt(1.0 - rho)).epsilon(0.12));
  CHECK(s.sigma_xy_m == Approx(sxy * std::sqrt(1.0 - std::pow(rho, 16))).epsilon(0.15));
  CHECK(s.sigma_theta_rad == Approx(sth * std::sqrt(1.0 - std::pow(rho, 16))).epsilon(0.15));
  CHECK(s.lag_xy >= 8);
  CHECK(s.lag_theta >= 8);
  // The old estimator (max_lag 1) is the lag-1 value, unchecked.
  StandstillNoiseOptions o;
  o.max_lag = 1;
  const StandstillNoise s1 = MeasureStandstillNoise(c, o);
  CHECK(s1.sigma_xy_m == s.lag1_sigma_xy_m);
  CHECK_FALSE(s1.plateau_xy);
}

TEST_CASE("standstill noise: a drift inside the standstills has no plateau; noise-free standstills get the floor") {
  std::mt19937_64 rng(13);
  std::normal_distribution<double> g(0.0, 1.0);
  // The heading wanders (a random walk of 1 mrad per sample): the
  // differences over k samples have sd sqrt(k) mrad, sqrt 2 more per
  // doubling, without end. (A steady creep would not count: the robust sd
  // is taken about the differences' median.)
  double walk = 0.0;
  const CampaignData drift = Campaign([&](int) {
    walk += 1e-3 * g(rng);
    return Pose2{1e-4 * g(rng), 1e-4 * g(rng), walk + 1e-4 * g(rng)};
  });
  const StandstillNoise d = MeasureStandstillNoise(drift);
  REQUIRE(d.measured);
  CHECK_FALSE(d.plateau_theta);
  CHECK(d.lag_theta == 16);
  CHECK(d.plateau_xy);

  const CampaignData still = Campaign([](int) { return Pose2{0.2, -0.1, 0.3}; });
  const StandstillNoiseOptions o;
  const StandstillNoise s = MeasureStandstillNoise(still, o);
  REQUIRE(s.measured);
  CHECK(s.lag1_sigma_xy_m == 0.0);
  CHECK(s.sigma_xy_m == o.floor_xy_m);
  CHECK(s.sigma_theta_rad == o.floor_theta_rad);
  CHECK(s.floored_xy);
  CHECK(s.floored_theta);

  StandstillNoiseOptions bad;
  bad.max_lag = 0;
  CHECK(bad.Check().find("max_lag") != std::string::npos);
  bad = {};
  bad.floor_xy_m = -1.0;
  CHECK(bad.Check().find("floor_xy_m") != std::string::npos);
}
