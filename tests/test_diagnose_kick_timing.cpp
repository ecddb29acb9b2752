// castor_kick when the first encoder count lags the start of the motion
// (issue 12: "castor kick fitted right, still unexplained"). The contract's
// kick happens when the robot starts to move; with acceleration limits and
// coarse encoders the first count comes tens of ms later, so at 20 Hz the
// last sample whose counts read still often shows the kicked heading
// already. The campaign comes from a small robot written here (not
// lib/simulation, which starts every motion at full speed):
//   - 1 kHz physics, trapezoidal speed profile: 0.4 m/s^2 up to 0.3 m/s in
//     legs, 0.4 rad/s^2 up to 1 rad/s in spot turns;
//   - 500 counts per revolution on 0.1 m wheels (0.63 mm per count) with a
//     random phase per wheel and run: the first count comes up to
//     sqrt(2 x 0.63 mm / 0.4 m/s^2) = 56 ms after the start, more than one
//     20 Hz sample;
//   - legs and turns end when the counts reach the nominal target;
//   - the kick applied at the instant the robot starts a leg (+kappa forward,
//     -kappa backward), none at spot turns;
//   - wheel noise N(0, k^2 |ds|) per wheel and step, ground truth with
//     0.3 mm / 1.5 mrad noise, E_d = 1.002, E_b = 1.01 (true geometry).
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <string>
#include <variant>
#include <vector>

#include "diagnosis/diagnose.hpp"
#include "diagnosis/pieces.hpp"
#include "simulation/campaign_sim.hpp"

using namespace umbmark;
using namespace umbmark::diag;
using Catch::Matchers::WithinRel;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kKappa = 0.010;  // rad
constexpr double kWheelbase = 0.4, kDiameter = 0.1, kTicks = 500.0;

/// The robot of the file comment, one run at a time.
class LaggingRobot {
 public:
  LaggingRobot(std::mt19937_64& g, std::string run, std::string direction) : g_(g) {
    out_.run = std::move(run);
    out_.direction = std::move(direction);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    phase_l_ = u(g);
    phase_r_ = u(g);
    Sample();
  }

  /// A leg of `distance` (signed) from standstill, ended on the counts.
  void Leg(double distance) {
    th_ += (distance > 0.0 ? 1.0 : -1.0) * kKappa;  // the kick: at the start
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
      const double done = dir * ((CountsR() - r0) - (CountsL() - l0)) * PerCount() / kWheelbase;
      if (done >= std::abs(angle)) break;
      w = Speed(w, std::abs(angle) - done, 1.0, 0.4, 0.02);
      const double s = 0.5 * kWheelbase * dir * w * kDt;
      Step(-s, s);
    }
  }

  void Pause(double seconds) {
    for (int i = 0; i < static_cast<int>(std::lround(seconds / kDt)); ++i) Step(0.0, 0.0);
  }

  TrajectoryRun Finish() { return std::move(out_); }

 private:
  static constexpr double kDt = 1e-3;
  static constexpr int kStepsPerSample = 50;  // 20 Hz

  static double PerCount() { return kPi * kDiameter / kTicks; }
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
    const double ds = 0.5 * (sl + sr), dth = (sr - sl) / (1.01 * kWheelbase);
    x_ += ds * std::cos(th_ + 0.5 * dth);
    y_ += ds * std::sin(th_ + 0.5 * dth);
    th_ += dth;
    if (++steps_ % kStepsPerSample == 0) Sample();
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
  TrajectoryRun out_;
  double phase_l_ = 0.0, phase_r_ = 0.0, wheel_l_ = 0.0, wheel_r_ = 0.0;
  double x_ = 0.0, y_ = 0.0, th_ = 0.0;
  long steps_ = 0;
};

/// 6 cw + 6 ccw squares of 2 m and 12 back-and-forth runs of 2 m, 1 s
/// pauses between motions (72 kicks).
std::vector<std::variant<EndpointData, TrajectoryData>> LaggingCampaign(std::uint64_t seed) {
  std::mt19937_64 g(seed);
  TrajectoryData squares, fwd_back;
  for (int r = 0; r < 12; ++r) {
    const bool cw = r % 2 == 0;
    LaggingRobot robot(g, std::to_string(r + 1), cw ? "cw" : "ccw");
    robot.Pause(1.0);
    for (int leg = 0; leg < 4; ++leg) {
      robot.Leg(2.0);
      robot.Pause(1.0);
      robot.Turn(cw ? -0.5 * kPi : 0.5 * kPi);
      robot.Pause(1.0);
    }
    squares.runs.push_back(robot.Finish());
  }
  for (int r = 0; r < 12; ++r) {
    LaggingRobot robot(g, std::to_string(r + 1), "fwd_back");
    robot.Pause(1.0);
    robot.Leg(2.0);
    robot.Pause(1.0);
    robot.Leg(-2.0);
    robot.Pause(1.0);
    fwd_back.runs.push_back(robot.Finish());
  }
  return {squares, fwd_back};
}

Manifest LaggingManifest() {
  RobotParams r;
  r.wheelbase_m = kWheelbase;
  r.wheel_diameter_left_m = r.wheel_diameter_right_m = kDiameter;
  r.ticks_per_rev = kTicks;
  return sim::StandardCampaignManifest(r, 2.0, 2.0, GroundTruthNoise{3e-4, 1.5e-3});
}

DiagnoseSummary DiagnoseWith(const PieceOptions& pieces) {
  DiagnoseOptions o;
  o.null_simulations = 100;
  o.seed = 1;
  o.threads = 2;
  o.pieces = pieces;
  return Diagnose(BuildCampaign(LaggingManifest(), LaggingCampaign(12012), pieces), o);
}

double FittedKappa(const DiagnoseSummary& d) {
  for (const auto& c : d.candidates)
    if (c.effect == sim::EffectKind::kCastorKick) return c.params.at("kappa");
  return 0.0;
}

}  // namespace

TEST_CASE("castor_kick: the kick at the motion's start, before a lagging first count", "[diagnose][kick-timing]") {
  const DiagnoseSummary d = DiagnoseWith(PieceOptions{});
  INFO(d.verdict_reason);
  CHECK(d.verdict == "castor_kick");
  // 72 kicks, heading noise of a first piece about 3.5 mrad: se ~0.4 mrad.
  CHECK_THAT(FittedKappa(d), WithinRel(kKappa, 0.10));
  CHECK(d.unexplained_fraction < 0.2);
}

TEST_CASE("castor_kick: the old placement (at the first count) leaves the kick in the standstills",
          "[diagnose][kick-timing]") {
  // The same campaign with every motion starting at its first moving
  // interval: the last still sample often shows the kick, so the
  // standstill pieces hold kicks the model does not predict. The issue's
  // symptom exactly: kappa fitted right (9.76 mrad) and still `unexplained`,
  // 32 % of the gap left on held-out runs (G = 1041 > 12); with the start
  // one sample earlier (test above) 0.08 % is left, kappa 9.85 mrad.
  PieceOptions old;
  old.start_before_first_count = false;
  const DiagnoseSummary d = DiagnoseWith(old);
  INFO(d.verdict_reason);
  CHECK(d.verdict == "unexplained");
  CHECK(d.unexplained_fraction > 0.2);
  CHECK_THAT(FittedKappa(d), WithinRel(kKappa, 0.10));
}
