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

TEST_CASE("standstill noise: a capture noise that jumps now and then is measured by its variance") {
  // A rigid body re-fitted to another subset of its markers: in each sample
  // independently, with probability p, the pose jumps by J (x) and Jth
  // (heading) for that sample, on top of a fine normal jitter s0. Closed
  // form: per-sample variance s0^2 + p (1 - p) J^2, white (r(k) = 0 for
  // k >= 1), so D(k) = 2 (s0^2 + p (1 - p) J^2) at every lag. The robust
  // scale sees the jitter (81 % of the differences have no jump): below
  // 1.5 s0 here. y has the jitter only. Tolerance: the differences'
  // variance has kurtosis about 10 here, so its sd over ~2000 differences
  // is about 7 %, of sigma 3.5 %; 12 % is 3.4 of them.
  const double p = 0.1, s0 = 5e-5, J = 5e-4, sth0 = 5e-4, Jth = 6e-3;
  const double sx = std::sqrt(s0 * s0 + p * (1 - p) * J * J), sth = std::sqrt(sth0 * sth0 + p * (1 - p) * Jth * Jth);
  for (unsigned seed : {21u, 22u, 23u}) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> g(0.0, 1.0);
    std::bernoulli_distribution jump(p);
    const CampaignData c = Campaign([&](int) {
      const bool j = jump(rng);
      return Pose2{s0 * g(rng) + (j ? J : 0.0), s0 * g(rng), sth0 * g(rng) + (j ? Jth : 0.0)};
    });
    const StandstillNoise s = MeasureStandstillNoise(c);
    REQUIRE(s.measured);
    // x and y pooled: sigma_xy^2 is the mean of their variances.
    CHECK(s.sigma_xy_m == Approx(std::sqrt(0.5 * (sx * sx + s0 * s0))).epsilon(0.12));
    CHECK(s.sigma_theta_rad == Approx(sth).epsilon(0.12));
    CHECK(s.plateau_xy);
    CHECK(s.lag_xy <= 2);
    CHECK(s.robust_sigma_xy_m < 1.5 * s0);
    CHECK(s.robust_sigma_theta_rad < 1.5 * sth0);
    // The estimator before (robust): the core, about 2 x / 3 x short.
    StandstillNoiseOptions o;
    o.robust = true;
    const StandstillNoise r = MeasureStandstillNoise(c, o);
    CHECK(r.sigma_xy_m == Approx(s.robust_sigma_xy_m));
    CHECK(r.sigma_theta_rad < 0.5 * sth);
  }
}

TEST_CASE("standstill noise: a drift inside the standstills has no plateau; noise-free standstills get the floor") {
  std::mt19937_64 rng(13);
  std::normal_distribution<double> g(0.0, 1.0);
  // The heading wanders (a random walk of 1 mrad per sample): the
  // differences over k samples have sd sqrt(k) mrad, sqrt 2 more per
  // doubling, without end. (A steady creep would not count: the sd is
  // taken about the differences' mean.)
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
