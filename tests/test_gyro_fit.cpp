// calibrate-lidar's gyro fit (FitGyroToScans, lib/calibration/lidar_calibrate)
// by Monte Carlo on drives simulated here, independently of the scan
// registration: a robot turns (spot turns and arcs with ramped rates, pauses,
// straight runs) on a 1 ms grid; a 100 Hz gyro reads scale * rate(t - tau) +
// bias + white noise; a 10 Hz lidar's keyframe measurements carry the true
// heading change between two scans plus each scan's own heading noise (so
// consecutive measurements, which share a scan, are correlated as the
// registrations are), their stamps off by a known scan clock offset.
// Known truth: scale 1.012, bias 0.006 rad/s, gyro noise 0.004 rad/s, tau
// 1.5 ms (a sample stamped t reads the rate held over [t - 2, t - 1] ms,
// the motion of t - 1.5 ms). The 95 % intervals are checked against the truth over 40 seeded
// drives, with the tolerance stated in sigmas.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "calibration/lidar_calibrate.hpp"
#include "calibration/lidar_pairs.hpp"
#include "core/errors.hpp"
#include "scan/gyro_calibration.hpp"

using namespace umbmark;
using namespace umbmark::calibration;

namespace {

struct GyroTruth {
  double scale = 1.012, bias = 0.006, noise_sd = 0.004;
  int lag_ms = 2;          // the sample stamped t reads the rate held over [t - lag, t - lag + 1] ms
  double Tau() const { return 1e-3 * (lag_ms - 0.5); }  // its stamp minus the time of the motion
  double scan_offset_s = 0.04;    // header stamp minus the scan's true time
  double heading_sd_rad = 5e-4;   // each keyframe scan's heading error
};

struct GyroDrive {
  std::vector<scan::GyroSample> gyro;
  std::vector<ScanPair> pairs;
};

constexpr std::int64_t kT0 = 1'700'000'000'000'000'000;

// A ramped turn: rate up at 3 rad/s^2 to a peak, hold, down, to turn `angle`.
void AppendTurn(std::vector<double>& rate, double angle, double peak) {
  const double acc = 3.0, dt = 1e-3, sign = angle < 0 ? -1.0 : 1.0;
  double turned = 0.0, r = 0.0;
  const double target = std::abs(angle);
  while (turned < target) {
    const double stop = r * r / (2.0 * acc);
    r = stop >= target - turned ? std::max(r - acc * dt, 0.02) : std::min(r + acc * dt, peak);
    turned += r * dt;
    rate.push_back(sign * r);
  }
}

GyroDrive Simulate(std::uint64_t seed, double seconds, const GyroTruth& g) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n01(0.0, 1.0);
  const auto steps = static_cast<std::size_t>(seconds * 1000.0);
  std::vector<double> rate(1000, 0.0);  // still for a second
  while (rate.size() < steps) {
    const double kind = u(rng);
    if (kind < 0.2) rate.insert(rate.end(), static_cast<std::size_t>(300 + 1500 * u(rng)), 0.0);  // pause or straight run
    else AppendTurn(rate, (u(rng) < 0.5 ? -1.0 : 1.0) * (0.5 + 3.0 * u(rng)), 0.4 + 0.8 * u(rng));
  }
  rate.resize(steps, 0.0);
  // Heading on the 1 ms grid (the rate held over each millisecond).
  std::vector<double> heading(steps + 1, 0.0);
  for (std::size_t i = 0; i < steps; ++i) heading[i + 1] = heading[i] + rate[i] * 1e-3;
  GyroDrive d;
  const auto lag = static_cast<std::size_t>(g.lag_ms);
  for (std::size_t i = lag; i < steps; i += 10)
    d.gyro.push_back({kT0 + static_cast<std::int64_t>(i) * 1'000'000, g.scale * rate[i - lag] + g.bias + g.noise_sd * n01(rng)});
  // Keyframes: a scan every 100 ms; a new keyframe after 0.6 rad or 3 s.
  std::size_t key = 1000;
  double key_error = g.heading_sd_rad * n01(rng);
  for (std::size_t i = key + 100; i + 100 < steps; i += 100) {
    const double turn = heading[i] - heading[key];
    if (std::abs(turn) < 0.6 && i - key < 3000) continue;
    const double error = g.heading_sd_rad * n01(rng);
    ScanPair p;
    p.t_a_ns = kT0 + static_cast<std::int64_t>(key) * 1'000'000 + std::llround(g.scan_offset_s * 1e9);
    p.t_b_ns = kT0 + static_cast<std::int64_t>(i) * 1'000'000 + std::llround(g.scan_offset_s * 1e9);
    p.lidar_a_T_lidar_b = {0.0, 0.0, turn + error - key_error};
    d.pairs.push_back(p);
    key = i;
    key_error = error;
  }
  return d;
}

}  // namespace

TEST_CASE("gyro Monte Carlo: scale, bias and time offset recovered, their 95 % intervals holding the truth") {
  // 40 two-minute drives (seeds 1-40), three quantities each = 120 checks.
  // With right intervals the count inside is Binomial(120, 0.95): mean 114,
  // sd 2.4; the test asks for >= 107 (2.9 sd below). The RMS of the
  // normalised errors (chi-square, 120 degrees of freedom: sd of the RMS
  // 0.065) must lie in [0.75, 1.25] (about 4 sd either way), no single one
  // beyond 4.5, and the mean scale error within 4 sd of the mean (a bias).
  // The simulation has no heading error common to a drive: the fit without
  // the model-error term for it.
  const GyroTruth g;
  GyroFitOptions no_term;
  no_term.heading_scale_sd = 0.0;
  int inside = 0, total = 0;
  double z2 = 0.0, worst = 0.0, scale_err = 0.0, scale_var = 0.0;
  const int drives = 40;
  for (int k = 1; k <= drives; ++k) {
    const GyroDrive d = Simulate(static_cast<std::uint64_t>(k), 120.0, g);
    const std::optional<GyroFit> f = FitGyroToScans(d.gyro, d.pairs, g.scan_offset_s, no_term);
    REQUIRE(f);
    REQUIRE(f->time_offset_s);
    const double z[3] = {(f->scale - g.scale) / f->scale_sd, (f->bias_rad_s - g.bias) / f->bias_sd,
                         (*f->time_offset_s - g.Tau()) / f->time_offset_sd};
    INFO("seed " << k << ": z " << z[0] << " " << z[1] << " " << z[2]);
    for (const double v : z) {
      inside += std::abs(v) <= 1.96 ? 1 : 0;
      z2 += v * v;
      worst = std::max(worst, std::abs(v));
      ++total;
    }
    scale_err += f->scale - g.scale;
    scale_var += f->scale_sd * f->scale_sd;
    // Each drive within the 0.3 % target for the gyro scale.
    CHECK(std::abs(f->scale / g.scale - 1.0) < 0.003);
  }
  const double rms = std::sqrt(z2 / total);
  const double mean_z = (scale_err / drives) / (std::sqrt(scale_var) / drives);
  INFO("inside " << inside << " of " << total << ", RMS z " << rms << ", worst " << worst << ", mean scale error in sd of the mean "
                 << mean_z);
  CHECK(inside >= 107);
  CHECK(rms >= 0.75);
  CHECK(rms <= 1.25);
  CHECK(worst <= 4.5);
  CHECK(std::abs(mean_z) <= 4.0);
}

TEST_CASE("gyro fit: the heading-scale model-error term widens the scale's interval only") {
  const GyroTruth g;
  const GyroDrive d = Simulate(7, 120.0, g);
  GyroFitOptions none;
  none.heading_scale_sd = 0.0;
  const auto a = FitGyroToScans(d.gyro, d.pairs, g.scan_offset_s, none);
  GyroFitOptions o;
  o.heading_scale_sd = 1e-4;
  const auto b = FitGyroToScans(d.gyro, d.pairs, g.scan_offset_s, o);
  REQUIRE(a);
  REQUIRE(b);
  CHECK(b->scale == a->scale);
  CHECK(b->bias_sd == a->bias_sd);
  CHECK(b->scale_sd * b->scale_sd == Approx(a->scale_sd * a->scale_sd + std::pow(1e-4 * a->scale, 2)).epsilon(1e-9));
}

TEST_CASE("gyro fit: too few measurements, no turns and bad options") {
  const GyroTruth g;
  GyroDrive d = Simulate(3, 120.0, g);
  std::vector<ScanPair> few(d.pairs.begin(), d.pairs.begin() + 5);
  CHECK_FALSE(FitGyroToScans(d.gyro, few, g.scan_offset_s));
  std::vector<ScanPair> still = d.pairs;
  for (auto& p : still) p.lidar_a_T_lidar_b.theta = 0.0;
  CHECK_FALSE(FitGyroToScans(d.gyro, still, g.scan_offset_s));
  GyroFitOptions o;
  o.heading_scale_sd = -1.0;
  CHECK_THROWS_AS(FitGyroToScans(d.gyro, d.pairs, g.scan_offset_s, o), InvalidOptions);
}
