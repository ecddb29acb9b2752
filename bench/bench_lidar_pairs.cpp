// The keyframe registrations of calibrate-lidar (calibration/lidar_pairs.hpp)
// against the simulator's truth (tests/support/lidar_sim.hpp): per drive,
// each measurement's error in the lidar frame of keyframe a, then over the
// drives
//   - the scale bias: the error along the lidar's direction of travel
//     regressed on the distance travelled (m/m; a registration that reads
//     translations long has a positive slope), with its t-value over the
//     drives' spread;
//   - likewise the rotation of the translations (lateral error per metre,
//     which the fit's lidar yaw takes as its own), the scale of the heading
//     changes (heading error per radian turned, the gyro scale's) and the
//     translation error per radian turned (the mount position's), each with
//     what the reported covariances predict for independent measurements
//     (an overestimate: consecutive measurements share a scan);
//   - the mean normalised squared error under the reported covariance (3 for
//     a covariance that is right up to the fit's one scale factor s^2, which
//     the joint fit estimates; its spread across measurements is what s^2
//     cannot absorb).
// For development seeds (1-200, 50001 on): 20001-20200, 30001-30200 and
// 40001-40200 were each run once as fresh sets by bench_lidar_joint.
// --fit also fits each drive twice (lidar_joint.hpp, from Censi's linear
// start): with the registrations as they are, and with each replaced by the
// truth plus Gaussian noise of its own reported covariance (times the s^2
// the first fit found); per wheel, mount and clock quantity the share of drives whose 95 %
// interval holds the truth and the mean and RMS normalised error: what the
// registrations' errors beyond their covariance do to the wheels.
//   bench_lidar_pairs BAGS MINUTES [FIRST_SEED] [--one-way] [--keep-shadow-edges] [--fit]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <vector>

#include <Eigen/Dense>

#include "calibration/lidar_joint.hpp"
#include "calibration/lidar_pairs.hpp"
#include "core/angles.hpp"
#include "support/lidar_sim.hpp"

int main(int argc, char** argv) {
  using namespace umbmark;
  if (argc < 3) {
    std::fprintf(stderr, "usage: bench_lidar_pairs BAGS MINUTES [FIRST_SEED] [--one-way]\n");
    return 2;
  }
  const int bags = std::atoi(argv[1]);
  const double minutes = std::atof(argv[2]);
  const std::uint64_t first = argc > 3 && argv[3][0] != '-' ? std::strtoull(argv[3], nullptr, 10) : 1;
  bool one_way = false, shadow = true, fit = false;
  for (int i = 3; i < argc; ++i) {
    if (std::strcmp(argv[i], "--one-way") == 0) one_way = true;
    if (std::strcmp(argv[i], "--keep-shadow-edges") == 0) shadow = false;
    if (std::strcmp(argv[i], "--fit") == 0) fit = true;
  }
  // [real, simulated] x [c_L, c_R, b]: normalised errors
  std::vector<double> zn[2][7];
  std::vector<double> slopes, pred_var, rots, rot_pred, hscales, hscale_pred, turn_t_pred;
  std::vector<Eigen::Vector2d> turn_t;
  double chi2_sum = 0.0, n_sum = 0.0, lat_sum = 0.0, th_sum = 0.0;
  for (int b = 0; b < bags; ++b) {
    testing::LidarSimConfig c;
    c.seed = first + static_cast<std::uint64_t>(b);
    c.minutes = minutes;
    const testing::LidarSimBag bag = testing::SimulateLidarDrive(c);
    calibration::PairOptions o;
    o.symmetric = !one_way;
    o.match.skip_shadow_edges = shadow;
    const calibration::PairResult pr = calibration::RegisterScanPairs(bag.scans, o);
    const std::int64_t t0 = 1'700'000'000'000'000'000, offset = std::llround(c.time_offset_s * 1e9);
    auto lidar_at = [&](std::int64_t stamp) {
      const auto i = static_cast<std::size_t>((stamp - offset - t0) / 1'000'000);
      return Compose(bag.truth[std::min(i, bag.truth.size() - 1)], c.mount);
    };
    // Per drive: err_along = slope * dist (least squares through 0).
    double sxy = 0.0, sxx = 0.0, chi2 = 0.0, lat = 0.0, th = 0.0, pred = 0.0;  // pred: sum d^2 var(along)
    double lxy = 0.0, lpred = 0.0;  // lateral error * d, sum d^2 var(lateral)
    double hxy = 0.0, hxx = 0.0, hpred = 0.0;  // heading error * heading change, sum change^2, sum change^2 var(heading)
    Eigen::Vector2d vxy = Eigen::Vector2d::Zero();  // translation error * heading change
    Eigen::Matrix2d vpred = Eigen::Matrix2d::Zero();  // sum change^2 cov(translation)
    int n = 0;
    for (const auto& p : pr.pairs) {
      if (!p.undetermined.empty()) continue;
      const Pose2 truth = Compose(Inverse(lidar_at(p.t_a_ns)), lidar_at(p.t_b_ns));
      const Pose2& z = p.lidar_a_T_lidar_b;
      const Eigen::Vector3d e(z.x - truth.x, z.y - truth.y, WrapAngle(z.theta - truth.theta));
      const double d = std::hypot(truth.x, truth.y);
      if (d > 0.05) {
        const double along = (e.x() * truth.x + e.y() * truth.y) / d;
        sxy += along * d;
        sxx += d * d;
        const double ux = truth.x / d, uy = truth.y / d;
        const auto& cv = p.covariance;
        pred += d * d * (ux * ux * cv[0] + 2 * ux * uy * cv[1] + uy * uy * cv[4]);
        lat += (-e.x() * truth.y + e.y() * truth.x) / d;
        lxy += (-e.x() * truth.y + e.y() * truth.x);
        lpred += d * d * (uy * uy * cv[0] - 2 * ux * uy * cv[1] + ux * ux * cv[4]);
      }
      th += e.z();
      hxy += e.z() * truth.theta;
      hxx += truth.theta * truth.theta;
      hpred += truth.theta * truth.theta * p.covariance[8];
      vxy += truth.theta * e.head<2>();
      Eigen::Matrix2d ct;
      ct << p.covariance[0], p.covariance[1], p.covariance[3], p.covariance[4];
      vpred += truth.theta * truth.theta * ct;
      Eigen::Matrix3d cov;
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) cov(r, k) = p.covariance[static_cast<std::size_t>(3 * r + k)];
      chi2 += e.dot(cov.ldlt().solve(e));
      ++n;
    }
    if (fit) {
      std::vector<calibration::WheelTravelSample> wheels(bag.wheels.begin(), bag.wheels.end());
      std::vector<calibration::ScanPair> used;
      for (const auto& p : pr.pairs)
        if (p.undetermined.empty()) used.push_back(p);
      const auto start = calibration::LinearCalibration(wheels, used, c.nominal_wheelbase_m).params;
      const double truth[7] = {c.c_left, c.c_right, c.wheelbase_m, c.mount.x, c.mount.y, c.mount.theta, c.time_offset_s};
      std::mt19937_64 rng(c.seed * 7919 + 1);
      std::normal_distribution<double> n01(0.0, 1.0);
      double s2 = 1.0;
      for (int mode = 0; mode < 2; ++mode) {
        std::vector<calibration::ScanPair> zs = used;
        if (mode == 1)
          for (auto& p : zs) {
            const Pose2 t = Compose(Inverse(lidar_at(p.t_a_ns)), lidar_at(p.t_b_ns));
            Eigen::Matrix3d cov;
            for (int r = 0; r < 3; ++r)
              for (int k = 0; k < 3; ++k) cov(r, k) = s2 * p.covariance[static_cast<std::size_t>(3 * r + k)];
            const Eigen::Vector3d e = cov.llt().matrixL() * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
            p.lidar_a_T_lidar_b = {t.x + e.x(), t.y + e.y(), t.theta + e.z()};
          }
        calibration::LidarJointOptions fo;
        fo.registration_scale_sd = 0.0;  // the fit's own covariance, without the model-error term
        const auto f = calibration::FitLidarJoint(wheels, zs, start, fo);
        if (mode == 0) s2 = f.registration_scale * f.registration_scale;
        const double est[7] = {f.params.c_left, f.params.c_right, f.params.wheelbase_m, f.params.mount.x, f.params.mount.y,
                               f.params.mount.theta, f.params.time_offset_s};
        for (int q = 0; q < 7; ++q) zn[mode][q].push_back((est[q] - truth[q]) / f.Sd(q));
        if (mode == 0)
          std::printf("seed %3llu fit: c_left %+.4f %% (sd %.4f), c_right %+.4f %% (sd %.4f), wheelbase %+.4f %% (sd %.4f)\n",
                      static_cast<unsigned long long>(c.seed), 100 * (est[0] / truth[0] - 1), 100 * f.Sd(0) / truth[0],
                      100 * (est[1] / truth[1] - 1), 100 * f.Sd(1) / truth[1], 100 * (est[2] / truth[2] - 1),
                      100 * f.Sd(2) / truth[2]);
      }
    }
    const double slope = sxx > 0 ? sxy / sxx : 0.0;
    slopes.push_back(slope);
    // The rotation of the translations (lateral error per metre, rad).
    const double rot = sxx > 0 ? lxy / sxx : 0.0;
    rots.push_back(rot);
    rot_pred.push_back(sxx > 0 ? chi2 / (3.0 * n) * lpred / (sxx * sxx) : 0.0);
    // The scale of the heading changes (heading error per radian turned).
    const double hscale = hxx > 0 ? hxy / hxx : 0.0;
    hscales.push_back(hscale);
    hscale_pred.push_back(hxx > 0 ? chi2 / (3.0 * n) * hpred / (hxx * hxx) : 0.0);
    // A translation error per radian turned (lidar frame): what the mount's
    // position takes as its own.
    const Eigen::Vector2d per_rad = hxx > 0 ? Eigen::Vector2d(vxy / hxx) : Eigen::Vector2d::Zero();
    turn_t.push_back(per_rad);
    turn_t_pred.push_back(hxx > 0 ? 0.5 * (chi2 / (3.0 * n) * vpred / (hxx * hxx)).trace() : 0.0);
    // The slope's variance the reported covariances predict (times the
    // drive's s^2 = mean chi2 / 3), independent measurements.
    pred_var.push_back(sxx > 0 ? chi2 / (3.0 * n) * pred / (sxx * sxx) : 0.0);
    chi2_sum += chi2;
    n_sum += n;
    lat_sum += lat;
    th_sum += th;
    std::printf("seed %3llu: %4d measurements, scale bias %+.2e m/m, rotation %+.2e rad, heading scale %+.2e, translation per rad %+.2e %+.2e m, mean chi2 %.2f (3 if the covariance is right)\n",
                static_cast<unsigned long long>(c.seed), n, slope, rot, hscale, per_rad.x(), per_rad.y(), chi2 / n);
  }
  double m = 0.0, v = 0.0;
  for (double s : slopes) m += s;
  m /= static_cast<double>(slopes.size());
  for (double s : slopes) v += (s - m) * (s - m);
  const double se = std::sqrt(v / (static_cast<double>(slopes.size()) - 1) / static_cast<double>(slopes.size()));
  double msq = 0.0, mp = 0.0;
  for (std::size_t i = 0; i < slopes.size(); ++i) {
    msq += slopes[i] * slopes[i];
    mp += pred_var[i];
  }
  msq /= static_cast<double>(slopes.size());
  mp /= static_cast<double>(slopes.size());
  std::printf("scale error per drive: RMS %.2e m/m, the reported covariances predict %.2e; the excess (a scale error the "
              "covariances do not carry) %.2e m/m\n",
              std::sqrt(msq), std::sqrt(mp), std::sqrt(std::max(0.0, msq - mp)));
  double rsq = 0.0, rp = 0.0, rm = 0.0;
  for (std::size_t i = 0; i < rots.size(); ++i) {
    rsq += rots[i] * rots[i];
    rp += rot_pred[i];
    rm += rots[i];
  }
  rsq /= static_cast<double>(rots.size());
  rp /= static_cast<double>(rots.size());
  rm /= static_cast<double>(rots.size());
  std::printf("rotation of the translations per drive (lateral error per metre): mean %+.2e rad, RMS %.2e rad, the reported "
              "covariances predict %.2e; the excess %.2e rad\n",
              rm, std::sqrt(rsq), std::sqrt(rp), std::sqrt(std::max(0.0, rsq - rp)));
  double hsq = 0.0, hp = 0.0, hm = 0.0;
  for (std::size_t i = 0; i < hscales.size(); ++i) {
    hsq += hscales[i] * hscales[i];
    hp += hscale_pred[i];
    hm += hscales[i];
  }
  const double nh = static_cast<double>(hscales.size());
  std::printf("scale of the heading changes per drive (heading error per radian turned): mean %+.2e, RMS %.2e, the reported "
              "covariances predict %.2e; the excess %.2e\n",
              hm / nh, std::sqrt(hsq / nh), std::sqrt(hp / nh), std::sqrt(std::max(0.0, hsq / nh - hp / nh)));
  double tsq = 0.0, tp = 0.0;
  Eigen::Vector2d tm = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < turn_t.size(); ++i) {
    tsq += 0.5 * turn_t[i].squaredNorm();
    tp += turn_t_pred[i];
    tm += turn_t[i];
  }
  const double nt = static_cast<double>(turn_t.size());
  std::printf("translation error per radian turned, per drive and axis: mean %+.2e %+.2e m, RMS %.2e m, the reported "
              "covariances predict %.2e; the excess %.2e m\n",
              tm.x() / nt, tm.y() / nt, std::sqrt(tsq / nt), std::sqrt(tp / nt), std::sqrt(std::max(0.0, tsq / nt - tp / nt)));
  std::printf("\n%d drives (%s): scale bias %+.2e m/m (t = %.1f; drive-to-drive sd %.2e), mean chi2 per measurement %.2f, "
              "mean lateral error %+.2e m, mean heading error %+.2e rad\n",
              bags, one_way ? "one way" : "both ways", m, m / se, std::sqrt(v / (static_cast<double>(slopes.size()) - 1)),
              chi2_sum / n_sum, lat_sum / n_sum, th_sum / n_sum);
  if (fit) {
    const char* names[7] = {"c_left", "c_right", "wheelbase", "mount x", "mount y", "mount yaw", "clock"};
    for (int mode = 0; mode < 2; ++mode)
      for (int q = 0; q < 7; ++q) {
        double mean = 0.0, ms = 0.0;
        int in = 0;
        for (double x : zn[mode][q]) {
          mean += x;
          ms += x * x;
          in += std::abs(x) <= 1.96 ? 1 : 0;
        }
        const double n = static_cast<double>(zn[mode][q].size());
        std::printf("%-28s %-9s coverage %5.1f %%, mean normalised error %+.2f, RMS %.2f\n",
                    mode == 0 ? "registrations as they are:" : "truth + their own noise:", names[q], 100.0 * in / n, mean / n,
                    std::sqrt(ms / n));
      }
  }
  return 0;
}
