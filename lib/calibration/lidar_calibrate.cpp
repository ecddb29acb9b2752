// calibrate-lidar's steps (see lidar_calibrate.hpp).
#include "calibration/lidar_calibrate.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <Eigen/Dense>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "scan/scan_matcher.hpp"

namespace umbmark::calibration {

namespace {

double Seconds(std::int64_t ns) { return static_cast<double>(ns) * 1e-9; }

// Travel of each wheel over [t_a, t_b] (linear interpolation of the cumulative travel).
std::pair<double, double> TravelBetween(const std::vector<WheelTravelSample>& w, std::int64_t ta, std::int64_t tb) {
  auto at = [&](std::int64_t t) -> std::pair<double, double> {
    if (t <= w.front().t_ns) return {w.front().left_m, w.front().right_m};
    if (t >= w.back().t_ns) return {w.back().left_m, w.back().right_m};
    const auto it = std::upper_bound(w.begin(), w.end(), t, [](std::int64_t v, const WheelTravelSample& s) { return v < s.t_ns; });
    const WheelTravelSample& b = *it;
    const WheelTravelSample& a = *(it - 1);
    const double u = static_cast<double>(t - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns);
    return {a.left_m + u * (b.left_m - a.left_m), a.right_m + u * (b.right_m - a.right_m)};
  };
  const auto [la, ra] = at(ta);
  const auto [lb, rb] = at(tb);
  return {lb - la, rb - ra};
}

// Drops the measurements the scene leaves open; refuses when they are many
// (a corridor), naming the direction in the room.
std::vector<ScanPair> DropOpen(const std::vector<ScanPair>& pairs, const LidarCalibrationOptions& o, LidarCalibration& out) {
  std::vector<ScanPair> kept;
  double sx = 0.0, sy = 0.0;  // doubled-angle mean of the open directions (an axis, not a heading)
  std::size_t heading_only = 0;
  for (const ScanPair& p : pairs) {
    if (p.undetermined.empty()) {
      kept.push_back(p);
      continue;
    }
    ++out.open_measurements;
    if (std::isnan(p.open_direction_rad)) {
      ++heading_only;
    } else {
      sx += std::cos(2.0 * p.open_direction_rad);
      sy += std::sin(2.0 * p.open_direction_rad);
    }
  }
  if (pairs.empty()) return kept;
  const double fraction = static_cast<double>(out.open_measurements) / static_cast<double>(pairs.size());
  if (fraction > o.max_open_fraction) {
    const std::string what =
        heading_only * 2 > out.open_measurements
            ? "the heading"
            : fmt::format("the position along the direction {:.0f} deg from the first scan's x axis (a corridor's length, "
                          "or walls beyond the lidar's range)",
                          Rad2Deg(WrapAngle(0.5 * std::atan2(sy, sx))));
    throw QualityGateError(fmt::format(
        "{} of {} scan measurements ({:.0f} %) leave {} undetermined (registration dilution of precision above {}): the "
        "scene cannot calibrate; drive where the walls face more than one way (a room, not a corridor)",
        out.open_measurements, pairs.size(), 100.0 * fraction, what, o.pairs.max_dilution));
  }
  if (out.open_measurements > 0)
    out.warnings.push_back(fmt::format("{} of {} scan measurements leave a direction undetermined (a corridor-like "
                                       "stretch) and are not used",
                                       out.open_measurements, pairs.size()));
  return kept;
}

// Sign agreement of two series: sum a_i b_i over sqrt(sum a^2 sum b^2).
double Agreement(const std::vector<double>& a, const std::vector<double>& b) {
  double ab = 0.0, aa = 0.0, bb = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ab += a[i] * b[i];
    aa += a[i] * a[i];
    bb += b[i] * b[i];
  }
  return aa > 0.0 && bb > 0.0 ? ab / std::sqrt(aa * bb) : 0.0;
}

// Whether the lidar runs mirrored (upside down): the scans turn against the
// wheels. Swapped wheels look the same to the scans; the gyro, when there
// is one, tells them apart (it turns with the true robot).
bool DecideMirror(const LidarCalibrationInput& in, const std::vector<ScanPair>& pairs, LidarCalibration& out) {
  std::vector<double> scan_turn, wheel_turn, gyro_turn;
  for (const ScanPair& p : pairs) {
    const auto [dl, dr] = TravelBetween(in.wheels, p.t_a_ns, p.t_b_ns);
    scan_turn.push_back(p.lidar_a_T_lidar_b.theta);
    wheel_turn.push_back((dr - dl) / in.nominal.wheelbase_m);
    if (!in.gyro.empty()) gyro_turn.push_back(scan::IntegrateRate(in.gyro, 0.0, p.t_a_ns, p.t_b_ns));
  }
  const double turned = std::accumulate(scan_turn.begin(), scan_turn.end(), 0.0, [](double s, double v) { return s + std::abs(v); });
  const double sw = Agreement(scan_turn, wheel_turn);
  if (turned < 1.0 || std::abs(sw) < 0.5) {
    if (in.tf_mount) return in.tf_mount->upside_down;
    if (turned >= 1.0)
      throw QualityGateError(fmt::format("the scans' heading changes and the wheels' do not agree in sign or size "
                                         "(correlation {:.2f}): a wheel's travel may run backwards or the wheel topic "
                                         "is not this robot's; check --wheels/--odometry",
                                         sw));
    return false;
  }
  if (sw > 0.0) {
    if (!gyro_turn.empty() && Agreement(gyro_turn, scan_turn) < -0.5)
      out.warnings.push_back("the gyro turns against both the scans and the wheels: the IMU is mounted upside down (its "
                             "scale comes out negative)");
    if (in.tf_mount && in.tf_mount->upside_down)
      out.warnings.push_back(fmt::format("/tf_static ({}) has the lidar upside down (roll pi), but its scans turn with the "
                                         "wheels: the lidar is the right way up",
                                         in.tf_mount->frames));
    return false;
  }
  if (!gyro_turn.empty()) {
    const double gs = Agreement(gyro_turn, scan_turn), gw = Agreement(gyro_turn, wheel_turn);
    if (gs > 0.5 && gw < -0.5)
      throw QualityGateError(
          "the wheels turn against the scans and the gyro: the left and right wheels are swapped (JointState: give "
          "--left-joint/--right-joint the other way round; Odometry: the controller's left_wheel_names and "
          "right_wheel_names are swapped); a swapped robot would calibrate to a negative wheelbase, so nothing is fitted");
    return true;  // the gyro turns with the wheels: the lidar is mirrored
  }
  if (!in.tf_mount)
    out.warnings.push_back("the scans turn against the wheels: the lidar is taken as mounted upside down (beam angles "
                           "mirrored); if instead the left and right wheels are swapped, swap them and run again (--imu "
                           "tells the two apart)");
  else if (!in.tf_mount->upside_down)
    out.warnings.push_back(fmt::format("the scans turn against the wheels although /tf_static ({}) has the lidar the "
                                       "right way up: taken as upside down (or the wheels are swapped; --imu tells)",
                                       in.tf_mount->frames));
  return true;
}

// The gyro's reading at t (linear between samples).
double GyroRateAt(const std::vector<scan::GyroSample>& g, std::int64_t t) {
  const auto it = std::lower_bound(g.begin(), g.end(), t, [](const scan::GyroSample& s, std::int64_t v) { return s.t_ns < v; });
  if (it == g.begin()) return g.front().rate_rad_s;
  if (it == g.end()) return g.back().rate_rad_s;
  const scan::GyroSample& b = *it;
  const scan::GyroSample& a = *(it - 1);
  const double u = static_cast<double>(t - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns);
  return a.rate_rad_s + u * (b.rate_rad_s - a.rate_rad_s);
}

void FitGyro(const LidarCalibrationInput& in, const std::vector<ScanPair>& pairs, const LidarCalibrationOptions& o,
             LidarCalibration& out) {
  if (in.gyro.empty()) return;
  const std::optional<GyroFit> g = FitGyroToScans(in.gyro, pairs, out.time_offset_s, o.gyro);
  if (!g) {
    out.warnings.push_back("the gyro covers fewer than 10 scan measurements, or they do not turn: no gyro scale or bias");
    return;
  }
  out.gyro_scale = g->scale;
  out.gyro_bias_rad_s = g->bias_rad_s;
  out.gyro_scale_sd = g->scale_sd;
  out.gyro_bias_sd = g->bias_sd;
  out.gyro_time_offset_s = g->time_offset_s;
  out.gyro_time_offset_sd = g->time_offset_sd;
}

// Heading turned left and right by the nominal wheels, and travel.
void DriveStats(const LidarCalibrationInput& in, LidarCalibration& out) {
  for (std::size_t k = 1; k < in.wheels.size(); ++k) {
    const double dl = in.wheels[k].left_m - in.wheels[k - 1].left_m, dr = in.wheels[k].right_m - in.wheels[k - 1].right_m;
    const double dth = (dr - dl) / in.nominal.wheelbase_m;
    (dth > 0 ? out.turned_left_rad : out.turned_right_rad) += std::abs(dth);
  }
}

std::string Percent(double rel) { return rel < 0.01 ? fmt::format("{:.2f} %", 100 * rel) : fmt::format("{:.1f} %", 100 * rel); }

// One parameter's excitation: not excited when the data shrink its prior's
// sd by less than half; determined within the target; weak in between.
ParameterExcitation Judge(const std::string& key, double sd, double prior_sd, double value, bool relative, double target,
                          double weak_factor) {
  ParameterExcitation e;
  e.key = key;
  e.relative = relative;
  e.target = target;
  e.ci95_half = 1.96 * sd / (relative ? std::abs(value) : 1.0);
  if (sd >= 0.5 * prior_sd || e.ci95_half > weak_factor * target) e.level = Excitation::kNotExcited;
  else if (e.ci95_half > target) e.level = Excitation::kWeak;
  return e;
}

// What to drive for each parameter not determined, from what the drive had.
void Advise(LidarCalibration& out) {
  const bool few_turns = std::min(out.turned_left_rad, out.turned_right_rad) < 4.0 * kPi;
  const bool few_straight = out.straight_m < 2.0;
  for (ParameterExcitation& e : out.excitation) {
    if (e.level == Excitation::kDetermined) continue;
    std::vector<std::string> add;
    std::string what;
    if (e.key == "wheelbase_m") {
      if (few_turns) add.push_back("spot turns and loops, two full turns each way");
      if (few_straight) add.push_back("straight runs of at least 2 m");
      what = "the wheelbase";
    } else if (e.key == "wheel_diameter_left_m" || e.key == "wheel_diameter_right_m") {
      if (few_straight) add.push_back("straight runs of at least 2 m");
      if (few_turns) add.push_back("loops in both directions");
      what = e.key == "wheel_diameter_left_m" ? "the left wheel's diameter" : "the right wheel's diameter";
    } else if (e.key == "lidar_mount") {
      if (few_turns) add.push_back("spot turns in both directions (they show the lidar's position)");
      if (few_straight) add.push_back("straight runs of at least 2 m (they show its yaw)");
      what = "the lidar's mount";
    } else if (e.key == "scan_time_offset_s") {
      add.push_back("brisk starts and stops, in straight runs and in turns (the clock shows where the speed changes)");
      what = "the scan clock offset";
    } else if (e.key == "gyro_scale") {
      if (few_turns) add.push_back("turns: spot turns and loops, two full turns each way");
      what = "the gyro scale";
    }
    if (add.empty()) add.push_back("more of the same driving (a longer bag)");
    std::string list;
    for (std::size_t i = 0; i < add.size(); ++i) list += (i == 0 ? "" : " and ") + add[i];
    std::string precision;
    if (e.level == Excitation::kNotExcited) precision = fmt::format("the drive does not determine {}", what);
    else if (e.relative) precision = fmt::format("{} is determined to {} only", what, Percent(e.ci95_half));
    else if (e.key == "scan_time_offset_s") precision = fmt::format("{} is determined to {:.1f} ms only", what, 1e3 * e.ci95_half);
    else precision = fmt::format("{} is determined to {:.1f} mm only", what, 1e3 * e.ci95_half);
    e.what_to_drive = fmt::format("add {}: {}", list, precision);
  }
}

// Physical covariance: [b, D_L, D_R, x, y, yaw, dt] from the fit's
// [c_L, c_R, b, x, y, yaw, dt], lengths times `scale`.
void PhysicalCovariance(const LidarJointFit& fit, const RobotParams& nominal, double scale, LidarCalibration& out) {
  Eigen::Matrix<double, kLidarParams, kLidarParams> c, t = Eigen::Matrix<double, kLidarParams, kLidarParams>::Zero();
  for (int r = 0; r < kLidarParams; ++r)
    for (int k = 0; k < kLidarParams; ++k) c(r, k) = fit.covariance[static_cast<std::size_t>(r * kLidarParams + k)];
  t(0, kWheelbase) = scale;
  t(1, kCLeft) = scale * nominal.wheel_diameter_left_m;
  t(2, kCRight) = scale * nominal.wheel_diameter_right_m;
  t(3, kMountX) = scale;
  t(4, kMountY) = scale;
  t(5, kMountYaw) = 1.0;
  t(6, kTimeOffset) = 1.0;
  const Eigen::Matrix<double, kLidarParams, kLidarParams> p = t * c * t.transpose();
  const bool gyro = out.gyro_scale.has_value();
  const int n = kLidarParams + (gyro ? 2 : 0);
  out.covariance_order = {"wheelbase_m", "wheel_diameter_left_m", "wheel_diameter_right_m", "lidar_mount.x_m",
                          "lidar_mount.y_m", "lidar_mount.yaw_rad", "scan_time_offset_s"};
  if (gyro) {
    out.covariance_order.push_back("gyro_scale");
    out.covariance_order.push_back("gyro_bias_rad_s");
  }
  out.covariance.assign(static_cast<std::size_t>(n * n), 0.0);
  for (int r = 0; r < kLidarParams; ++r)
    for (int k = 0; k < kLidarParams; ++k) out.covariance[static_cast<std::size_t>(r * n + k)] = p(r, k);
  if (gyro) {
    out.covariance[static_cast<std::size_t>(7 * n + 7)] = out.gyro_scale_sd * out.gyro_scale_sd;
    out.covariance[static_cast<std::size_t>(8 * n + 8)] = out.gyro_bias_sd * out.gyro_bias_sd;
  }
}

// The fitted mount against /tf_static's: a warning where they differ by more
// than both 3 sd and 1 cm / 1 deg.
void CompareWithTf(const LidarCalibrationInput& in, LidarCalibration& out) {
  if (!in.tf_mount) return;
  const StaticMount& tf = *in.tf_mount;
  const double sx = (out.x_ci95[1] - out.x_ci95[0]) / 3.92, sy = (out.y_ci95[1] - out.y_ci95[0]) / 3.92;
  const double syaw = (out.yaw_ci95[1] - out.yaw_ci95[0]) / 3.92;
  const double dx = tf.pose.x - out.mount.x, dy = tf.pose.y - out.mount.y, dyaw = WrapAngle(tf.pose.theta - out.mount.theta);
  std::vector<std::string> diff;
  if (tf.upside_down != out.upside_down)
    diff.push_back(fmt::format("/tf_static has it {} but its scans run {}", tf.upside_down ? "upside down" : "the right way up",
                               out.upside_down ? "mirrored" : "unmirrored"));
  if (std::abs(dx) > std::max(3 * sx, 0.01)) diff.push_back(fmt::format("x differs by {:+.1f} mm", 1e3 * dx));
  if (std::abs(dy) > std::max(3 * sy, 0.01)) diff.push_back(fmt::format("y differs by {:+.1f} mm", 1e3 * dy));
  if (std::abs(dyaw) > std::max(3 * syaw, Deg2Rad(1.0))) diff.push_back(fmt::format("yaw differs by {:+.2f} deg", Rad2Deg(dyaw)));
  if (!diff.empty())
    out.warnings.push_back(fmt::format("/tf_static's mount of the lidar ({}: x {:.4f} m, y {:.4f} m, yaw {:.4f} rad) disagrees "
                                       "with the fit: {}; update the URDF with the fitted origin (--ros2 writes it)",
                                       tf.frames, tf.pose.x, tf.pose.y, tf.pose.theta, fmt::join(diff, "; ")));
}

// Where the drive starts and ends, by the scans: each of the (up to 10)
// scans taken while the wheels stand still before the first motion is
// registered directly against the one as many places from the end after
// the last motion, from the keyframe chain's estimate, and the results are
// averaged. The chain's own estimate drifts along the drive (6 mm, 0.4 %,
// over a 100 s drive ending 1.5 m from its start); a single direct pair
// carries its registration noise (about 1 mm for 180 beams). The chain's
// estimate when no direct registration succeeds (too few pairs, an open
// direction, or more than 0.3 m or 0.3 rad from the chain), with a warning.
Pose2 FirstToLast(const LidarCalibrationInput& in, const PairResult& pr, const LidarCalibrationOptions& o, LidarCalibration& out) {
  const Pose2 chain = pr.lidar0_T_lidar_last;
  const WheelTravelSample& w0 = in.wheels.front();
  const WheelTravelSample& w1 = in.wheels.back();
  auto moved = [](const WheelTravelSample& a, const WheelTravelSample& b) {
    return std::abs(a.left_m - b.left_m) > 1e-4 || std::abs(a.right_m - b.right_m) > 1e-4;
  };
  std::int64_t first_motion = w1.t_ns, last_motion = w0.t_ns;
  for (const auto& w : in.wheels)
    if (moved(w, w0)) {
      first_motion = w.t_ns;
      break;
    }
  for (auto it = in.wheels.rbegin(); it != in.wheels.rend(); ++it)
    if (moved(*it, w1)) {
      last_motion = it->t_ns;
      break;
    }
  const std::int64_t margin = 200'000'000;  // 0.2 s: beyond any scan clock offset the fit accepts here
  double sx = 0.0, sy = 0.0, sth = 0.0;
  std::size_t used = 0, tried = 0;
  for (std::size_t k = 0; k < 10 && k < in.scans.size() / 2; ++k) {
    const scan::LaserScan& a = in.scans[k];
    const scan::LaserScan& b = in.scans[in.scans.size() - 1 - k];
    if (k > 0 && (a.t_ns + margin > first_motion || b.t_ns - margin < last_motion)) break;
    ++tried;
    const scan::ScanModel model(a);
    // Every pair counts here: a far registration pairs too few points without
    // the background beside the edges (skip_shadow_edges).
    scan::MatchOptions match = o.pairs.match;
    match.skip_shadow_edges = false;
    const scan::MatchResult m = scan::MatchScan(model, scan::ScanPoints(b), chain, match);
    const bool ok = m.pairs >= o.pairs.min_points && m.PairedFraction() >= o.pairs.min_paired_fraction &&
                    scan::UndeterminedDirections(m.information, m.pairs, 0.0, o.pairs.max_dilution).empty() &&
                    std::hypot(m.pose.x - chain.x, m.pose.y - chain.y) <= 0.3 &&
                    std::abs(WrapAngle(m.pose.theta - chain.theta)) <= 0.3;
    if (!ok) continue;
    sx += m.pose.x;
    sy += m.pose.y;
    sth += WrapAngle(m.pose.theta - chain.theta);
    ++used;
  }
  if (used > 0) {
    const double n = static_cast<double>(used);
    return {sx / n, sy / n, WrapAngle(chain.theta + sth / n)};
  }
  out.warnings.push_back(fmt::format("the last scan{} do(es) not register against the first: the start-to-end distance for "
                                     "--distance-m comes from the chain of all registrations{}",
                                     tried > 1 ? "s" : "",
                                     pr.lost > 0 ? fmt::format(", dead-reckoned over {} failed one(s)", pr.lost) : ""));
  return chain;
}

// The robot's start-to-end distance the scans measured (the first and the
// last scan through the fitted mount), for --distance-m; the factor that
// makes it D.
double DistanceScale(const LidarCalibrationInput& in, const PairResult& pr, const LidarCalibrationOptions& o, LidarCalibration& out) {
  Pose2 chain = FirstToLast(in, pr, o, out);
  if (out.upside_down) chain = {chain.x, -chain.y, -chain.theta};
  const Pose2 robot = Compose(out.mount, Compose(chain, Inverse(out.mount)));
  const double d = std::hypot(robot.x, robot.y);
  if (d < 0.5)
    throw QualityGateError(fmt::format("--distance-m {}: the drive ends {:.3f} m from where it starts by the scans; a "
                                       "measured distance needs a start and an end mark at least 1 m apart",
                                       *in.distance_m, d));
  const double s = *in.distance_m / d;
  if (std::abs(s - 1.0) > 0.05)
    out.warnings.push_back(fmt::format("--distance-m {} m against the scans' {:.4f} m: the lidar's ranges would be off by "
                                       "{:+.1f} %; check the distance",
                                       *in.distance_m, d, 100.0 * (1.0 / s - 1.0)));
  return s;
}

}  // namespace

// Gyro scale, bias and time offset: the integral of the reading over each
// measurement's interval [t_a, t_b] (the scan stamps less the fitted clock
// offset) is
//
//     scale * heading change + bias * (t_b - t_a) - tau * (w(t_b) - w(t_a)),
//
// tau being the gyro's stamp minus the time of the motion it measures (a
// filter's group delay, a sample that averages the next interval) and w the
// reading at the interval's ends: to first order a shifted window gains the
// rate at one end and loses it at the other. Least squares, with the lag-1
// sandwich covariance (consecutive intervals share a scan). Without the
// third term a delay of half a millisecond biases the scale by about one
// standard deviation of a 5-minute drive: spot turns start inside one
// keyframe interval at full rate and end inside another with less, so the
// end terms do not cancel. The term also absorbs an error of the fitted
// scan clock, which shifts every window alike. Drives whose rate never
// changes fit scale and bias alone.
std::optional<GyroFit> FitGyroToScans(const std::vector<scan::GyroSample>& gyro, const std::vector<ScanPair>& pairs,
                                      double scan_time_offset_s, const GyroFitOptions& o) {
  if (const std::string err = o.Validate(); !err.empty()) throw InvalidOptions(err);
  const bool fit_delay = o.fit_delay;
  const std::int64_t offset = std::llround(scan_time_offset_s * 1e9);
  using Vec3 = Eigen::Vector3d;
  std::vector<Vec3> rows;
  std::vector<double> ys;
  for (const ScanPair& p : pairs) {
    const std::int64_t ta = p.t_a_ns - offset, tb = p.t_b_ns - offset;
    if (ta < gyro.front().t_ns || tb > gyro.back().t_ns) continue;
    rows.emplace_back(p.lidar_a_T_lidar_b.theta, Seconds(tb - ta), GyroRateAt(gyro, tb) - GyroRateAt(gyro, ta));
    ys.push_back(scan::IntegrateRate(gyro, 0.0, ta, tb));
  }
  if (rows.size() < 10) return std::nullopt;
  Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
  Vec3 g = Vec3::Zero();
  for (std::size_t i = 0; i < rows.size(); ++i) {
    h += rows[i] * rows[i].transpose();
    g += rows[i] * ys[i];
  }
  if (std::abs(h.topLeftCorner<2, 2>().determinant()) < 1e-12 * h.topLeftCorner<2, 2>().squaredNorm()) return std::nullopt;
  // The delay only where the rate changes enough to tell it: its sd under
  // 10 ms for a 0.01 rad residual, i.e. its information (the Schur
  // complement of the rate-difference column) over 1 (rad/s)^2; else scale
  // and bias alone.
  const Eigen::Vector2d cross = h.block<2, 1>(0, 2);
  const double info = h(2, 2) - cross.dot(h.topLeftCorner<2, 2>().ldlt().solve(cross));
  const bool delay = fit_delay && info > 1.0;
  if (!delay) {
    h.row(2).setZero();
    h.col(2).setZero();
    h(2, 2) = 1.0;
    g(2) = 0.0;
    for (Vec3& r : rows) r(2) = 0.0;
  }
  const Vec3 x = h.ldlt().solve(g);
  Eigen::Matrix3d meat = Eigen::Matrix3d::Zero();
  std::vector<Vec3> score;
  for (std::size_t i = 0; i < rows.size(); ++i) score.push_back(rows[i] * (ys[i] - rows[i].dot(x)));
  for (std::size_t i = 0; i < score.size(); ++i) {
    meat += score[i] * score[i].transpose();
    if (i + 1 < score.size()) meat += score[i] * score[i + 1].transpose() + score[i + 1] * score[i].transpose();
  }
  const Eigen::Matrix3d hi = h.inverse();
  const Eigen::Matrix3d cov = hi * meat * hi;
  GyroFit out;
  out.measurements = rows.size();
  out.scale = x(0);
  out.bias_rad_s = x(1);
  // Model error: a scale error g common to the drive's heading changes moves
  // the scale by -g times itself.
  out.scale_sd = std::sqrt(std::max(0.0, cov(0, 0)) + std::pow(o.heading_scale_sd * x(0), 2));
  out.bias_sd = std::sqrt(std::max(0.0, cov(1, 1)));
  if (delay && x(0) != 0.0) {
    out.time_offset_s = -x(2) / x(0);
    out.time_offset_sd = std::sqrt(std::max(0.0, cov(2, 2))) / std::abs(x(0));
  }
  return out;
}

std::string GyroFitOptions::Validate() const {
  if (!(heading_scale_sd >= 0.0 && heading_scale_sd < 0.1))
    return fmt::format("heading_scale_sd = {}: must be in [0, 0.1)", heading_scale_sd);
  return {};
}

const char* ExcitationToString(Excitation e) {
  switch (e) {
    case Excitation::kDetermined: return "determined";
    case Excitation::kWeak: return "weak";
    case Excitation::kNotExcited: return "not_excited";
  }
  return "?";
}

std::string LidarCalibrationOptions::Validate() const {
  if (const std::string e = pairs.Validate(); !e.empty()) return "pairs." + e;
  if (const std::string e = fit.Validate(); !e.empty()) return "fit." + e;
  if (const std::string e = gyro.Validate(); !e.empty()) return "gyro." + e;
  for (const auto& [name, v] :
       {std::pair{"max_open_fraction", max_open_fraction}, std::pair{"min_drive_s", min_drive_s},
        std::pair{"target_wheelbase_rel", target_wheelbase_rel}, std::pair{"target_diameter_rel", target_diameter_rel},
        std::pair{"target_position_m", target_position_m}, std::pair{"target_yaw_rad", target_yaw_rad},
        std::pair{"target_offset_s", target_offset_s}, std::pair{"target_gyro_scale_rel", target_gyro_scale_rel},
        std::pair{"weak_factor", weak_factor}})
    if (!(v > 0.0) || !std::isfinite(v)) return fmt::format("{} = {}: must be a finite number > 0", name, v);
  return {};
}

// The steps of lidar_calibrate.hpp in order; about 90 lines of filling the
// result in, kept in one place so the order of the refusals reads at once.
LidarCalibration CalibrateLidar(const LidarCalibrationInput& in, const LidarCalibrationOptions& o) {
  if (const std::string err = o.Validate(); !err.empty()) throw InvalidOptions(err);
  if (const std::string err = in.nominal.Check(); !err.empty()) throw InvalidOptions("robot parameters: " + err);
  LidarCalibration out;
  out.scans = in.scans.size();
  if (in.wheels.size() < 2 || in.scans.size() < 2)
    throw QualityGateError(fmt::format("{} wheel sample(s) and {} scan(s): nothing to calibrate", in.wheels.size(), in.scans.size()));
  out.duration_s = Seconds(std::min(in.wheels.back().t_ns, in.scans.back().t_ns) - std::max(in.wheels.front().t_ns, in.scans.front().t_ns));
  if (out.duration_s < o.min_drive_s)
    throw QualityGateError(fmt::format("the wheels and the scans overlap for {:.1f} s; at least {:.0f} s are needed: record "
                                       "a few minutes of driving (straight runs, spot turns and loops in both directions)",
                                       std::max(0.0, out.duration_s), o.min_drive_s));
  const PairResult pr = RegisterScanPairs(in.scans, o.pairs);
  out.lost = pr.lost;
  std::vector<ScanPair> pairs = DropOpen(pr.pairs, o, out);
  out.upside_down = DecideMirror(in, pairs, out);
  if (out.upside_down)
    for (ScanPair& p : pairs) p = MirrorPair(p);
  DriveStats(in, out);
  out.linear = LinearCalibration(in.wheels, pairs, in.nominal.wheelbase_m);
  out.straight_m = out.linear.straight_m;
  LidarJointParams start = out.linear.params;
  if (!(start.c_left > 0.0 && start.c_right > 0.0 && start.wheelbase_m > 0.0)) {
    start.c_left = start.c_right = 1.0;
    start.wheelbase_m = in.nominal.wheelbase_m;
  }
  out.fit = FitLidarJoint(in.wheels, pairs, start, o.fit);
  const LidarJointParams& f = out.fit.params;
  out.measurements = out.fit.measurements;
  if (!(f.c_left > 0.0 && f.c_right > 0.0 && f.wheelbase_m > 0.0))
    throw QualityGateError(fmt::format("the fit gives a wheelbase of {:.4f} m and wheel scales {:.4f} / {:.4f}: not a robot; "
                                       "check that --wheels/--odometry and --scan come from the same robot and drive",
                                       f.wheelbase_m, f.c_left, f.c_right));
  out.mount = f.mount;
  out.time_offset_s = f.time_offset_s;
  double scale = 1.0;
  out.scale_source = "lidar_ranges";
  if (in.distance_m) {
    scale = DistanceScale(in, pr, o, out);
    out.scale_source = "distance_m";
    out.mount.x *= scale;
    out.mount.y *= scale;
  }
  out.parameters = in.nominal;
  out.parameters.wheelbase_m = scale * f.wheelbase_m;
  out.parameters.wheel_diameter_left_m = scale * f.c_left * in.nominal.wheel_diameter_left_m;
  out.parameters.wheel_diameter_right_m = scale * f.c_right * in.nominal.wheel_diameter_right_m;
  out.wheel_separation_multiplier = out.parameters.wheelbase_m / in.nominal.wheelbase_m;
  out.left_wheel_radius_multiplier = scale * f.c_left;
  out.right_wheel_radius_multiplier = scale * f.c_right;
  FitGyro(in, pairs, o, out);
  PhysicalCovariance(out.fit, in.nominal, scale, out);
  const std::size_t n = out.covariance_order.size();
  auto sd = [&](std::size_t i) { return std::sqrt(std::max(0.0, out.covariance[i * n + i])); };
  auto ci = [&](double v, double s) { return std::array<double, 2>{v - 1.96 * s, v + 1.96 * s}; };
  out.x_ci95 = ci(out.mount.x, sd(3));
  out.y_ci95 = ci(out.mount.y, sd(4));
  out.yaw_ci95 = ci(out.mount.theta, sd(5));
  out.time_offset_ci95 = ci(out.time_offset_s, sd(6));
  const auto& ps = out.fit.prior_sd;
  out.excitation.push_back(Judge("wheelbase_m", sd(0), scale * ps[kWheelbase], out.parameters.wheelbase_m, true,
                                 o.target_wheelbase_rel, o.weak_factor));
  out.excitation.push_back(Judge("wheel_diameter_left_m", sd(1), scale * ps[kCLeft] * in.nominal.wheel_diameter_left_m,
                                 out.parameters.wheel_diameter_left_m, true, o.target_diameter_rel, o.weak_factor));
  out.excitation.push_back(Judge("wheel_diameter_right_m", sd(2), scale * ps[kCRight] * in.nominal.wheel_diameter_right_m,
                                 out.parameters.wheel_diameter_right_m, true, o.target_diameter_rel, o.weak_factor));
  ParameterExcitation mx = Judge("lidar_mount", std::max(sd(3), sd(4)), ps[kMountX], 0.0, false, o.target_position_m, o.weak_factor);
  const ParameterExcitation my = Judge("lidar_mount", sd(5), ps[kMountYaw], 0.0, false, o.target_yaw_rad, o.weak_factor);
  if (my.level > mx.level) mx.level = my.level;
  out.excitation.push_back(mx);
  out.excitation.push_back(Judge("scan_time_offset_s", sd(6), ps[kTimeOffset], 0.0, false, o.target_offset_s, o.weak_factor));
  if (out.gyro_scale)
    out.excitation.push_back(Judge("gyro_scale", out.gyro_scale_sd, 1.0, *out.gyro_scale, true, o.target_gyro_scale_rel, o.weak_factor));
  Advise(out);
  out.wheels_determined = std::any_of(out.excitation.begin(), out.excitation.begin() + 3,
                                      [](const ParameterExcitation& e) { return e.level != Excitation::kNotExcited; });
  CompareWithTf(in, out);
  return out;
}

}  // namespace umbmark::calibration
