// A fast simulator of a calibration drive for calibrate-lidar's tests and
// bench: a differential-drive robot with known wheel diameters and
// wheelbase drives "ordinary" teleop motion (straight runs, spot turns,
// arcs, stops, chosen at random from a seed and kept inside a safe box) in a
// furnished ray-cast room; the wheels report travel as the nominal
// diameters make it, with Chong-Kleeman noise (variance k^2 |d| per wheel);
// a 2-D lidar at a chosen mounting pose (possibly upside down: beam angles
// mirrored) returns ranges with Gaussian noise and 1 % dropouts, its header
// stamps off by a chosen clock offset; a gyro reads scale * rate + bias +
// noise. Scans are instantaneous (taken at the first ray's time) unless
// sweep_fraction says otherwise (each beam cast at its own time, the header
// stamp at the first ray or, stamp_at_end, the last).
//
//   room (metres, origin at its centre):  8 x 6 walls, a niche, a cupboard,
//   a table with four legs, two pillars, a sofa; the robot stays in
//   |x| < 2.3, |y| < 1.6.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "calibration/lidar_joint.hpp"
#include "core/angles.hpp"
#include "core/pose2.hpp"
#include "scan/gyro_calibration.hpp"
#include "scan/laser_scan.hpp"

namespace umbmark::testing {

struct Segment {
  double x0, y0, x1, y1;
};

/// The simulated truth and the sensors' settings.
struct LidarSimConfig {
  std::uint64_t seed = 1;
  double minutes = 5.0;
  double nominal_wheelbase_m = 0.28;
  double wheelbase_m = 0.2856;     ///< true
  double c_left = 0.997, c_right = 1.004;  ///< true / nominal diameter
  double wheel_k = 1e-3;           ///< wheel travel noise [m^1/2]
  Pose2 mount{0.12, -0.03, 0.35};  ///< robot_T_lidar (mirrored frame when upside down)
  bool upside_down = false;
  double time_offset_s = 0.04;     ///< header stamp minus true scan time
  double range_sd_m = 0.01;
  double scan_hz = 10.0;
  int beams = 360;
  double range_max_m = 10.0;
  double gyro_scale = 1.012, gyro_bias = 0.006, gyro_sd = 0.004;
  /// Drive: "ordinary" (mixed), "straight" (back and forth, no turns but the
  /// reversals in place... none: the robot drives straight back and forth).
  bool turns = true;
  /// Sweep timing: 0 = instantaneous scans (every beam at the first ray's
  /// time, time_increment 0); else the beams are cast one after another
  /// over this fraction of the scan period from where the lidar is at each
  /// beam's own time (motion distortion), and time_increment says so.
  double sweep_fraction = 0.0;
  /// Header stamp at the sweep's last ray instead of its first (a driver
  /// convention); time_offset_s stays the first ray's stamp offset.
  bool stamp_at_end = false;
  bool corridor = false;  ///< a 2.4 m wide corridor whose ends are beyond the range instead of the room
};

struct LidarSimBag {
  std::vector<calibration::WheelTravelSample> wheels;  ///< 50 Hz
  std::vector<scan::LaserScan> scans;
  std::vector<scan::GyroSample> gyro;                  ///< 100 Hz
  std::vector<Pose2> truth;                            ///< robot pose every 1 ms
  double distance_start_end_m = 0.0;                   ///< true distance between the first and the last pose
};

inline std::vector<Segment> FurnishedRoom(bool corridor) {
  std::vector<Segment> s;
  auto box = [&](double x0, double y0, double x1, double y1) {
    s.push_back({x0, y0, x1, y0});
    s.push_back({x1, y0, x1, y1});
    s.push_back({x1, y1, x0, y1});
    s.push_back({x0, y1, x0, y0});
  };
  auto pillar = [&](double cx, double cy, double r) {
    for (int k = 0; k < 8; ++k) {
      const double a0 = k * kPi / 4, a1 = (k + 1) * kPi / 4;
      s.push_back({cx + r * std::cos(a0), cy + r * std::sin(a0), cx + r * std::cos(a1), cy + r * std::sin(a1)});
    }
  };
  if (corridor) {
    s.push_back({-40, -1.2, 40, -1.2});
    s.push_back({-40, 1.2, 40, 1.2});
    return s;
  }
  // Walls with a niche in the north wall.
  s.push_back({-4, -3, 4, -3});
  s.push_back({4, -3, 4, 3});
  s.push_back({4, 3, 1.0, 3});
  s.push_back({1.0, 3, 1.0, 3.6});
  s.push_back({1.0, 3.6, -0.5, 3.6});
  s.push_back({-0.5, 3.6, -0.5, 3});
  s.push_back({-0.5, 3, -4, 3});
  s.push_back({-4, 3, -4, -3});
  box(2.9, -2.9, 3.9, -1.6);     // cupboard
  box(-3.9, 1.8, -2.6, 2.9);     // sofa
  for (double lx : {-1.2, 0.0})  // table legs (5 cm)
    for (double ly : {-2.7, -2.2}) box(lx, ly, lx + 0.05, ly + 0.05);
  pillar(2.9, 2.2, 0.15);
  pillar(-3.2, -2.2, 0.2);
  s.push_back({3.0, 0.5, 3.6, 1.3});  // a slanted screen
  return s;
}

/// Range along a ray from (x, y) at angle a, or +inf.
inline double CastRay(const std::vector<Segment>& room, double x, double y, double a) {
  const double dx = std::cos(a), dy = std::sin(a);
  double best = std::numeric_limits<double>::infinity();
  for (const Segment& g : room) {
    const double ex = g.x1 - g.x0, ey = g.y1 - g.y0;
    const double den = dx * ey - dy * ex;
    if (std::abs(den) < 1e-12) continue;
    const double wx = g.x0 - x, wy = g.y0 - y;
    const double t = (wx * ey - wy * ex) / den, u = (wx * dy - wy * dx) / den;
    if (t > 0.0 && u >= 0.0 && u <= 1.0 && t < best) best = t;
  }
  return best;
}

namespace sim_detail {

// One manoeuvre: travel ds and turn dth together along a trapezoidal progress
// profile (speed <= 0.3 m/s, rate <= 1.2 rad/s, accelerations 0.6 m/s^2 and
// 2.5 rad/s^2), or stand still for `pause` seconds.
struct Manoeuvre {
  double ds = 0, dth = 0, pause = 0;
};

inline std::vector<double> ProgressRates(const Manoeuvre& m, double dt) {
  std::vector<double> rates;
  if (m.pause > 0) {
    rates.assign(static_cast<std::size_t>(m.pause / dt), 0.0);
    return rates;
  }
  const double peak = std::min(std::abs(m.ds) > 1e-9 ? 0.3 / std::abs(m.ds) : 1e9, std::abs(m.dth) > 1e-9 ? 1.2 / std::abs(m.dth) : 1e9);
  const double acc = std::min(std::abs(m.ds) > 1e-9 ? 0.6 / std::abs(m.ds) : 1e9, std::abs(m.dth) > 1e-9 ? 2.5 / std::abs(m.dth) : 1e9);
  double u = 0.0, r = 0.0;
  while (u < 1.0) {
    const double remaining = 1.0 - u;
    const double stop_dist = r * r / (2 * acc);
    if (stop_dist >= remaining) r = std::max(r - acc * dt, 0.02 * peak);
    else r = std::min(r + acc * dt, peak);
    u += r * dt;
    rates.push_back(r - std::max(0.0, u - 1.0) / dt);
  }
  return rates;
}

inline bool InsideBox(const Pose2& p, const Manoeuvre& m, bool corridor) {
  const double bx = corridor ? 30.0 : 2.3, by = corridor ? 0.5 : 1.6;
  Pose2 q = p;
  for (int k = 1; k <= 20; ++k) {
    const double ds = m.ds / 20, dth = m.dth / 20;
    q = {q.x + ds * std::cos(q.theta + dth / 2), q.y + ds * std::sin(q.theta + dth / 2), q.theta + dth};
    if (std::abs(q.x) > bx || std::abs(q.y) > by) return false;
  }
  return true;
}

inline Manoeuvre Pick(std::mt19937_64& rng, const Pose2& p, bool turns, bool corridor) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  if (!turns) {
    // Straight back and forth along x.
    const double go = (p.x > 0 ? -1.0 : 1.0) * (1.5 + u(rng));
    return u(rng) < 0.2 ? Manoeuvre{0, 0, 0.5 + u(rng)} : Manoeuvre{go, 0, 0};
  }
  for (int attempt = 0; attempt < 30; ++attempt) {
    const double kind = u(rng);
    Manoeuvre m;
    if (kind < 0.1) m.pause = 0.3 + 1.5 * u(rng);
    else if (kind < 0.4) m.ds = (u(rng) < 0.85 ? 1.0 : -0.4) * (0.5 + 2.0 * u(rng));
    else if (kind < 0.6) m.dth = (u(rng) < 0.5 ? -1.0 : 1.0) * (0.5 + 2.5 * u(rng));
    else {
      const double radius = 0.3 + 0.9 * u(rng), angle = (u(rng) < 0.5 ? -1.0 : 1.0) * (1.0 + 3.5 * u(rng));
      m.ds = radius * std::abs(angle);
      m.dth = angle;
    }
    if (m.pause > 0 || InsideBox(p, m, corridor)) return m;
  }
  // Turn towards the centre.
  const double to_centre = WrapAngle(std::atan2(-p.y, -p.x) - p.theta);
  return {0.0, to_centre, 0.0};
}

}  // namespace sim_detail

/// Simulates one drive. Deterministic for a seed.
inline LidarSimBag SimulateLidarDrive(const LidarSimConfig& c) {
  using sim_detail::Manoeuvre;
  std::mt19937_64 rng(c.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const double dt = 1e-3;
  const auto steps = static_cast<std::size_t>(c.minutes * 60.0 / dt);
  // Commanded (v, w) per ms: a still second first, then manoeuvres.
  std::vector<double> v(steps, 0.0), w(steps, 0.0);
  Pose2 plan{0.0, 0.0, 0.0};
  std::size_t k = 1000;
  while (k < steps) {
    const Manoeuvre m = sim_detail::Pick(rng, plan, c.turns, c.corridor);
    for (const double r : sim_detail::ProgressRates(m, dt)) {
      if (k >= steps) break;
      v[k] = m.ds * r;
      w[k] = m.dth * r;
      plan = {plan.x + v[k] * dt * std::cos(plan.theta + 0.5 * w[k] * dt), plan.y + v[k] * dt * std::sin(plan.theta + 0.5 * w[k] * dt),
              plan.theta + w[k] * dt};
      ++k;
    }
  }
  for (std::size_t i = std::max<std::size_t>(steps, 1000) - 1000; i < steps; ++i) v[i] = w[i] = 0.0;  // still at the end
  LidarSimBag bag;
  bag.truth.reserve(steps + 1);
  Pose2 p;
  bag.truth.push_back(p);
  double true_l = 0.0, true_r = 0.0, meas_l = 0.0, meas_r = 0.0, last_l = 0.0, last_r = 0.0;
  const std::int64_t t0 = 1'700'000'000'000'000'000;
  const auto wheel_every = static_cast<std::size_t>(0.02 / dt), gyro_every = static_cast<std::size_t>(0.01 / dt);
  const auto scan_every = static_cast<std::size_t>(std::lround(1.0 / c.scan_hz / dt));
  const std::vector<Segment> room = FurnishedRoom(c.corridor);
  const double beam_s = c.sweep_fraction / c.scan_hz / c.beams;  // time_increment
  auto lidar_at = [&](double t_s) {  // lidar pose t_s seconds after the start (poses so far)
    const double f = std::min(t_s / dt, static_cast<double>(bag.truth.size() - 1));
    const auto k0 = static_cast<std::size_t>(f);
    const std::size_t k1 = std::min(k0 + 1, bag.truth.size() - 1);
    const double u = f - static_cast<double>(k0);
    const Pose2& a = bag.truth[k0];
    const Pose2& b = bag.truth[k1];
    return Compose(Pose2{a.x + u * (b.x - a.x), a.y + u * (b.y - a.y), a.theta + u * WrapAngle(b.theta - a.theta)}, c.mount);
  };
  std::vector<std::pair<std::size_t, int>> sweeping;  // (scan, next beam): cast as the poses arrive
  for (std::size_t i = 0; i <= steps; ++i) {
    const std::int64_t t_ns = t0 + static_cast<std::int64_t>(i) * 1'000'000;
    if (i % wheel_every == 0) {
      const double dl = true_l - last_l, dr = true_r - last_r;
      meas_l += dl / c.c_left + c.wheel_k * std::sqrt(std::abs(dl)) * n01(rng);
      meas_r += dr / c.c_right + c.wheel_k * std::sqrt(std::abs(dr)) * n01(rng);
      last_l = true_l;
      last_r = true_r;
      bag.wheels.push_back({t_ns, meas_l, meas_r});
    }
    const double rate = i < steps ? w[i] : 0.0;
    if (i % gyro_every == 0) bag.gyro.push_back({t_ns, c.gyro_scale * rate + c.gyro_bias + c.gyro_sd * n01(rng)});
    if (i % scan_every == 37 % scan_every) {
      scan::LaserScan s;
      s.t_ns = t_ns + static_cast<std::int64_t>(std::llround((c.time_offset_s + (c.stamp_at_end ? beam_s * (c.beams - 1) : 0.0)) * 1e9));
      s.angle_min = -kPi;
      s.angle_increment = 2.0 * kPi / c.beams;
      s.range_min = 0.1;
      s.range_max = c.range_max_m;
      s.time_increment = beam_s;
      s.scan_time = 1.0 / c.scan_hz;
      s.ranges.assign(static_cast<std::size_t>(c.beams), std::numeric_limits<float>::quiet_NaN());
      bag.scans.push_back(std::move(s));
      sweeping.emplace_back(bag.scans.size() - 1, 0);
    }
    // Beams whose time has come (all at once without a sweep), cast from
    // the lidar's pose then; random numbers drawn in beam order.
    for (auto& [j, next] : sweeping) {
      scan::LaserScan& s = bag.scans[j];
      const double first_s = static_cast<double>(s.t_ns - t0) * 1e-9 - c.time_offset_s - (c.stamp_at_end ? beam_s * (c.beams - 1) : 0.0);
      for (; next < c.beams; ++next) {
        const int b = next;
        const double tb = first_s + b * beam_s;
        if (tb > static_cast<double>(i) * dt + 1e-12) break;
        const Pose2 lidar = lidar_at(tb);
        const double beam = s.angle_min + b * s.angle_increment;
        const double a = lidar.theta + (c.upside_down ? -beam : beam);
        double r = CastRay(room, lidar.x, lidar.y, a);
        if (r > c.range_max_m || u01(rng) < 0.01) r = std::numeric_limits<double>::infinity();
        else r += c.range_sd_m * n01(rng);
        s.ranges[static_cast<std::size_t>(b)] = static_cast<float>(r);
      }
    }
    sweeping.erase(std::remove_if(sweeping.begin(), sweeping.end(), [&](const auto& js) { return js.second >= c.beams; }),
                   sweeping.end());
    if (i == steps) break;
    // True motion over the ms (wheel speeds from the commanded v, w).
    const double dl = (v[i] - 0.5 * w[i] * c.wheelbase_m) * dt, dr = (v[i] + 0.5 * w[i] * c.wheelbase_m) * dt;
    true_l += dl;
    true_r += dr;
    const double ds = 0.5 * (dl + dr), dth = (dr - dl) / c.wheelbase_m;
    p = {p.x + ds * std::cos(p.theta + 0.5 * dth), p.y + ds * std::sin(p.theta + 0.5 * dth), p.theta + dth};
    bag.truth.push_back(p);
  }
  bag.distance_start_end_m = std::hypot(bag.truth.back().x - bag.truth.front().x, bag.truth.back().y - bag.truth.front().y);
  return bag;
}

}  // namespace umbmark::testing
