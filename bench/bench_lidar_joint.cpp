// Accuracy, interval coverage and speed of calibrate-lidar's joint fit on
// simulated drives (tests/support/lidar_sim.hpp: a furnished ray-cast room,
// wheel noise k = 1 mm/m^1/2, 1 cm range noise, lidar at (0.12, -0.03) m
// turned 0.35 rad, scan clock +40 ms, gyro scale 1.012 and bias 0.006
// rad/s). Per bag: the errors against the truth; over the bags: RMS and
// largest error, and the share of bags whose 95 % interval holds the truth,
// per quantity; and the CPU time of registration and fit.
// The simulated gyro's sample at t is the mean rate over the millisecond
// after t: its stamp is 0.5 ms before the motion it measures (a gyro time
// offset of -0.5 ms, which the fit estimates relative to the scans as the
// fitted clock puts them). Median 95 % half-widths show
// whether an interval is still useful.
//   bench_lidar_joint BAGS MINUTES [FIRST_SEED] [--upside-down] [--quiet]
//                     [--one-way] [--no-gyro-offset] [--sweep FRACTION] [--stamp-end]
//                     [--no-deskew]
// --sweep times the beams over that share of the scan period (motion
// distortion; time_increment set) and --stamp-end stamps each scan at its
// last ray (the clock's truth is then the offset plus the sweep);
// --no-deskew registers the sweeps as if instantaneous.
// --one-way registers each keyframe pair one way only and --no-gyro-offset
// fits the gyro's scale and bias alone (the fit before both were added).
// bench/lidar_joint_bench.sh runs 200 five-minute bags and a 10-minute one.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "calibration/lidar_calibrate.hpp"
#include "core/errors.hpp"
#include "support/lidar_sim.hpp"

namespace {

double CpuSeconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

struct Stat {
  const char* name;
  const char* unit;
  double scale;  // to the printed unit
  double sum2 = 0, worst = 0;
  int covered = 0, n = 0;
  std::vector<double> halves{};
  void Add(double err, double half) {
    halves.push_back(half);
    sum2 += err * err;
    worst = std::max(worst, std::abs(err));
    covered += std::abs(err) <= half ? 1 : 0;
    ++n;
  }
};

}  // namespace

int main(int argc, char** argv) {
  using namespace umbmark;
  if (argc < 3) {
    std::fprintf(stderr, "usage: bench_lidar_joint BAGS MINUTES [FIRST_SEED] [--upside-down] [--quiet]\n");
    return 2;
  }
  const int bags = std::atoi(argv[1]);
  const double minutes = std::atof(argv[2]);
  const std::uint64_t first = argc > 3 && argv[3][0] != '-' ? std::strtoull(argv[3], nullptr, 10) : 1;
  bool upside = false, quiet = false, one_way = false, no_gyro_offset = false, stamp_end = false, no_deskew = false;
  double sweep = 0.0;
  for (int i = 3; i < argc; ++i) {
    if (std::strcmp(argv[i], "--one-way") == 0) one_way = true;
    if (std::strcmp(argv[i], "--no-gyro-offset") == 0) no_gyro_offset = true;
    if (std::strcmp(argv[i], "--upside-down") == 0) upside = true;
    if (std::strcmp(argv[i], "--quiet") == 0) quiet = true;
    if (std::strcmp(argv[i], "--stamp-end") == 0) stamp_end = true;
    if (std::strcmp(argv[i], "--no-deskew") == 0) no_deskew = true;
    if (std::strcmp(argv[i], "--sweep") == 0 && i + 1 < argc) sweep = std::atof(argv[i + 1]);
  }
  Stat st[] = {{"wheelbase", "%", 100.0}, {"D_left", "%", 100.0},   {"D_right", "%", 100.0}, {"mount x", "mm", 1e3},
               {"mount y", "mm", 1e3},    {"mount yaw", "deg", Rad2Deg(1.0)}, {"clock", "ms", 1e3}, {"gyro scale", "%", 100.0},
               {"gyro bias", "mrad/s", 1e3}, {"gyro clock", "ms", 1e3}};
  // Censi's linear step (the fit's start): RMS errors of b, D_L, D_R [%], x, y [mm], yaw [deg].
  double lin2[6] = {0, 0, 0, 0, 0, 0};
  int lin_n = 0;
  double sim_s = 0, fit_s = 0;
  int failures = 0;
  for (int b = 0; b < bags; ++b) {
    testing::LidarSimConfig c;
    c.seed = first + static_cast<std::uint64_t>(b);
    c.minutes = minutes;
    c.upside_down = upside;
    c.sweep_fraction = sweep;
    c.stamp_at_end = stamp_end;
    // The clock's truth: header stamp minus the first ray's time.
    const double clock_truth = c.time_offset_s + (stamp_end ? sweep / c.scan_hz * (c.beams - 1) / c.beams : 0.0);
    double t0 = CpuSeconds();
    const testing::LidarSimBag bag = testing::SimulateLidarDrive(c);
    sim_s += CpuSeconds() - t0;
    calibration::LidarCalibrationInput in;
    in.wheels = bag.wheels;
    in.scans = bag.scans;
    in.gyro = bag.gyro;
    in.nominal.wheelbase_m = c.nominal_wheelbase_m;
    in.nominal.wheel_diameter_left_m = in.nominal.wheel_diameter_right_m = 0.066;
    t0 = CpuSeconds();
    try {
      calibration::LidarCalibrationOptions options;
      options.pairs.symmetric = !one_way;
      options.pairs.deskew = !no_deskew;
      options.gyro.fit_delay = !no_gyro_offset;
      const auto r = calibration::CalibrateLidar(in, options);
      fit_s += CpuSeconds() - t0;
      const std::size_t n = r.covariance_order.size();
      auto sd = [&](std::size_t i) { return std::sqrt(r.covariance[i * n + i]); };
      const double tb = c.wheelbase_m, tl = c.c_left * 0.066, tr = c.c_right * 0.066;
      const double err[9] = {r.parameters.wheelbase_m / tb - 1, r.parameters.wheel_diameter_left_m / tl - 1,
                             r.parameters.wheel_diameter_right_m / tr - 1, r.mount.x - c.mount.x, r.mount.y - c.mount.y,
                             WrapAngle(r.mount.theta - c.mount.theta), r.time_offset_s - clock_truth,
                             r.gyro_scale ? *r.gyro_scale / c.gyro_scale - 1 : 0.0,
                             r.gyro_bias_rad_s ? *r.gyro_bias_rad_s - c.gyro_bias : 0.0};
      const double half[9] = {1.96 * sd(0) / tb, 1.96 * sd(1) / tl, 1.96 * sd(2) / tr, 1.96 * sd(3), 1.96 * sd(4),
                              1.96 * sd(5), 1.96 * sd(6), 1.96 * r.gyro_scale_sd / c.gyro_scale, 1.96 * r.gyro_bias_sd};
      for (int i = 0; i < 9; ++i) st[i].Add(err[i], half[i]);
      // The sample averages the next millisecond (-0.5 ms), seen through the
      // fitted scan clock (its error shifts every integration window alike).
      const double gyro_offset_truth = -0.0005 + (r.time_offset_s - clock_truth);
      if (r.gyro_time_offset_s) st[9].Add(*r.gyro_time_offset_s - gyro_offset_truth, 1.96 * r.gyro_time_offset_sd);
      const auto& lp = r.linear.params;
      const double lin[6] = {100 * (lp.wheelbase_m / tb - 1), 100 * (lp.c_left / c.c_left - 1), 100 * (lp.c_right / c.c_right - 1),
                             1e3 * (lp.mount.x - c.mount.x), 1e3 * (lp.mount.y - c.mount.y),
                             Rad2Deg(WrapAngle(lp.mount.theta - c.mount.theta))};
      for (int i = 0; i < 6; ++i) lin2[i] += lin[i] * lin[i];
      ++lin_n;
      if (!quiet) {
        std::printf("seed %3llu: %zu scans, %zu meas (%zu out), s %.2f k %.2e up %d |", static_cast<unsigned long long>(c.seed),
                    r.scans, r.measurements, r.fit.outliers, r.fit.registration_scale, r.fit.wheel_noise_k, r.upside_down ? 1 : 0);
        for (int i = 0; i < 9; ++i) std::printf(" %s %+.3f(%.3f)", st[i].name, err[i] * st[i].scale, half[i] * st[i].scale);
        std::printf(" | z");
        for (int i = 0; i < 9; ++i) std::printf(" %+.2f", half[i] > 0 ? 1.96 * err[i] / half[i] : 0.0);
        std::printf("\n");
      }
    } catch (const std::exception& e) {
      ++failures;
      std::printf("seed %llu: %s\n", static_cast<unsigned long long>(c.seed), e.what());
    }
  }
  std::printf("\n%d bags of %.1f min (%d refused); simulation %.2f s/bag, registration + fit %.2f s/bag CPU\n", bags, minutes,
              failures, sim_s / bags, fit_s / bags);
  std::printf("%-11s %10s %10s %9s %14s %16s\n", "quantity", "RMS error", "largest", "coverage", "(binomial sd)",
              "median half-width");
  for (Stat& s : st)
    if (s.n > 0) {
      const double p = static_cast<double>(s.covered) / s.n;
      std::nth_element(s.halves.begin(), s.halves.begin() + static_cast<long>(s.halves.size() / 2), s.halves.end());
      std::printf("%-11s %7.4f %-6s %7.4f %-6s %6.1f %% %10.1f %% %12.4f %s\n", s.name, std::sqrt(s.sum2 / s.n) * s.scale, s.unit,
                  s.worst * s.scale, s.unit, 100.0 * p, 100.0 * std::sqrt(p * (1 - p) / s.n),
                  s.halves[s.halves.size() / 2] * s.scale, s.unit);
    }
  if (lin_n > 0)
    std::printf("Censi's linear step alone (the start values), RMS: wheelbase %.3f %%, D_left %.3f %%, D_right %.3f %%, "
                "mount x %.2f mm, y %.2f mm, yaw %.3f deg\n",
                std::sqrt(lin2[0] / lin_n), std::sqrt(lin2[1] / lin_n), std::sqrt(lin2[2] / lin_n), std::sqrt(lin2[3] / lin_n),
                std::sqrt(lin2[4] / lin_n), std::sqrt(lin2[5] / lin_n));
  return 0;
}
