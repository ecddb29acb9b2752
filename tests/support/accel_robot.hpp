// A small robot with acceleration limits and coarse encoders, written for
// the diagnosis' tests (not lib/simulation, which starts every motion at
// full speed):
//   - 1 kHz physics, trapezoidal speed profile: 0.4 m/s^2 up to 0.3 m/s in
//     legs, 0.4 rad/s^2 up to 1 rad/s in spot turns, creeping at least
//     0.01 m/s (legs) and 0.02 rad/s (turns) to reach the target;
//   - 500 counts per revolution on 0.1 m wheels (0.63 mm per count) with a
//     random phase per wheel and run; legs and turns end when the counts
//     reach the nominal target;
//   - a castor kick kappa at the instant the robot starts a leg (+kappa
//     forward, -kappa backward), none at spot turns;
//   - wheel noise N(0, k^2 |ds|) per wheel and step, k = 1e-3 m^1/2, ground
//     truth with 0.3 mm / 1.5 mrad noise, E_d = 1.002, E_b = 1.01 (true
//     geometry), wheelbase 0.4 m; samples at sample_rate_hz (20 Hz default).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <string>
#include <utility>

#include <variant>
#include <vector>

#include "core/runs.hpp"
#include "formats/manifest.hpp"
#include "simulation/campaign_sim.hpp"

namespace umbmark::testing {

inline constexpr double kAccelPi = 3.14159265358979323846;
inline constexpr double kAccelKappa = 0.010;  // rad
inline constexpr double kAccelWheelbase = 0.4, kAccelDiameter = 0.1, kAccelTicks = 500.0;

/// The robot of the file comment, one run at a time.
class AccelRobot {
 public:
  /// kappa: castor kick [rad] at every leg's start; sample_rate_hz: a
  /// divisor of the 1 kHz physics rate.
  AccelRobot(std::mt19937_64& g, std::string run, std::string direction, double kappa = kAccelKappa,
             int sample_rate_hz = 20)
      : g_(g), kappa_(kappa), steps_per_sample_(1000 / sample_rate_hz) {
    out_.run = std::move(run);
    out_.direction = std::move(direction);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    phase_l_ = u(g);
    phase_r_ = u(g);
    Sample();
  }

  /// A leg of `distance` (signed) from standstill, ended on the counts.
  void Leg(double distance) {
    th_ += (distance > 0.0 ? 1.0 : -1.0) * kappa_;  // the kick: at the start
    const double dir = distance > 0.0 ? 1.0 : -1.0, l0 = CountsL(), r0 = CountsR();
    double v = 0.0;
    for (;;) {
      const double done = 0.5 * dir * ((CountsL() - l0) + (CountsR() - r0)) * PerCount();
      if (done >= std::abs(distance)) break;
      v = Speed(v, std::abs(distance) - done, 0.3, 0.4, 0.01);
      Step(dir * v * kDt, dir * v * kDt);
    }
  }

  /// A spot turn of `angle` (signed), ended on the counts.
  void Turn(double angle) {
    const double dir = angle > 0.0 ? 1.0 : -1.0, l0 = CountsL(), r0 = CountsR();
    double w = 0.0;
    for (;;) {
      const double done = dir * ((CountsR() - r0) - (CountsL() - l0)) * PerCount() / kAccelWheelbase;
      if (done >= std::abs(angle)) break;
      w = Speed(w, std::abs(angle) - done, 1.0, 0.4, 0.02);
      const double s = 0.5 * kAccelWheelbase * dir * w * kDt;
      Step(-s, s);
    }
  }

  void Pause(double seconds) {
    for (int i = 0; i < static_cast<int>(std::lround(seconds / kDt)); ++i) Step(0.0, 0.0);
  }

  /// Samples recorded so far.
  std::size_t Samples() const { return out_.t_s.size(); }

  TrajectoryRun Finish() { return std::move(out_); }

 private:
  static constexpr double kDt = 1e-3;

  static double PerCount() { return kAccelPi * kAccelDiameter / kAccelTicks; }
  double CountsL() const { return std::floor(wheel_l_ / PerCount() + phase_l_); }
  double CountsR() const { return std::floor(wheel_r_ / PerCount() + phase_r_); }

  /// Trapezoidal profile: accelerate at `accel`, brake to stop at the
  /// target, creep at least `creep` to reach it.
  static double Speed(double current, double left, double top, double accel, double creep) {
    return std::max(creep, std::min({top, current + accel * kDt, std::sqrt(2.0 * accel * left)}));
  }

  /// Commanded wheel rotation (as travel of nominal wheels) dl, dr; the
  /// ground moves with the true diameters (E_d = 1.002) and wheelbase
  /// (E_b = 1.01) plus wheel noise k = 1e-3 m^1/2.
  void Step(double dl, double dr) {
    wheel_l_ += dl;
    wheel_r_ += dr;
    std::normal_distribution<double> n01(0.0, 1.0);
    const double E_d = 1.002, c_l = 2.0 / (E_d + 1.0), c_r = 2.0 / (1.0 / E_d + 1.0);
    double sl = dl * c_l, sr = dr * c_r;
    sl += 1e-3 * std::sqrt(std::abs(sl)) * n01(g_);
    sr += 1e-3 * std::sqrt(std::abs(sr)) * n01(g_);
    const double ds = 0.5 * (sl + sr), dth = (sr - sl) / (1.01 * kAccelWheelbase);
    x_ += ds * std::cos(th_ + 0.5 * dth);
    y_ += ds * std::sin(th_ + 0.5 * dth);
    th_ += dth;
    if (++steps_ % steps_per_sample_ == 0) Sample();
  }

  void Sample() {
    std::normal_distribution<double> n01(0.0, 1.0);
    out_.t_s.push_back(static_cast<double>(steps_) * kDt);
    out_.ticks_left.push_back(static_cast<std::int64_t>(CountsL()));
    out_.ticks_right.push_back(static_cast<std::int64_t>(CountsR()));
    out_.gt_x_m.push_back(x_ + 3e-4 * n01(g_));
    out_.gt_y_m.push_back(y_ + 3e-4 * n01(g_));
    out_.gt_theta_rad.push_back(th_ + 1.5e-3 * n01(g_));
    out_.lines.push_back(out_.t_s.size() + 1);
  }

  std::mt19937_64& g_;
  double kappa_;
  int steps_per_sample_;
  TrajectoryRun out_;
  double phase_l_ = 0.0, phase_r_ = 0.0, wheel_l_ = 0.0, wheel_r_ = 0.0;
  double x_ = 0.0, y_ = 0.0, th_ = 0.0;
  long steps_ = 0;
};

/// 6 cw + 6 ccw squares of 2 m and 12 back-and-forth runs of 2 m, 1 s
/// pauses between motions (72 starts of a leg), castor kick kappa, samples
/// at sample_rate_hz.
inline std::vector<std::variant<EndpointData, TrajectoryData>> AccelCampaign(std::uint64_t seed, double kappa,
                                                                            int sample_rate_hz) {
  std::mt19937_64 g(seed);
  TrajectoryData squares, fwd_back;
  for (int r = 0; r < 12; ++r) {
    const bool cw = r % 2 == 0;
    AccelRobot robot(g, std::to_string(r + 1), cw ? "cw" : "ccw", kappa, sample_rate_hz);
    robot.Pause(1.0);
    for (int leg = 0; leg < 4; ++leg) {
      robot.Leg(2.0);
      robot.Pause(1.0);
      robot.Turn(cw ? -0.5 * kAccelPi : 0.5 * kAccelPi);
      robot.Pause(1.0);
    }
    squares.runs.push_back(robot.Finish());
  }
  for (int r = 0; r < 12; ++r) {
    AccelRobot robot(g, std::to_string(r + 1), "fwd_back", kappa, sample_rate_hz);
    robot.Pause(1.0);
    robot.Leg(2.0);
    robot.Pause(1.0);
    robot.Leg(-2.0);
    robot.Pause(1.0);
    fwd_back.runs.push_back(robot.Finish());
  }
  return {squares, fwd_back};
}

/// The manifest of AccelCampaign: the robot's nominal geometry, ground-truth
/// noise as stated.
inline Manifest AccelManifest() {
  RobotParams r;
  r.wheelbase_m = kAccelWheelbase;
  r.wheel_diameter_left_m = r.wheel_diameter_right_m = kAccelDiameter;
  r.ticks_per_rev = kAccelTicks;
  return sim::StandardCampaignManifest(r, 2.0, 2.0, GroundTruthNoise{3e-4, 1.5e-3});
}

}  // namespace umbmark::testing
