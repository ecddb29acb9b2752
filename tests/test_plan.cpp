// lib/planning: the sandwich covariance of the plain least-squares fit
// against a closed form and against a direct simulation of the noise it
// models; the design search's monotonicity and its honesty about the scale.
#include <cmath>
#include <random>

#include <Eigen/Dense>
#include <catch2/catch.hpp>
#include <fmt/format.h>

#include "core/errors.hpp"
#include "kinematics/diff_drive.hpp"
#include "planning/advice.hpp"
#include "planning/information.hpp"
#include "planning/motions.hpp"
#include "planning/plan.hpp"

using namespace umbmark;
using namespace umbmark::planning;

namespace {

RobotParams Robot() {
  RobotParams r;
  r.wheelbase_m = 0.4;
  r.wheel_diameter_left_m = r.wheel_diameter_right_m = 0.1;
  return r;
}

}  // namespace

TEST_CASE("motions: a square's duration and wheel travel", "[plan]") {
  MotionTiming t;  // 0.3 m/s, 1 rad/s, 1 s pauses
  const std::vector<Motion> m = RunMotions(RunKind::kSquareCw, 2.0, {}, 0.4, t);
  // 4 legs of 2 m at 0.3 m/s, 4 turns of pi/2 at 1 rad/s, 7 inner pauses of 1 s, 2 end pauses of 1 s.
  CHECK(MotionsDuration(m) == Approx(4 * 2.0 / 0.3 + 2.0 * 3.14159265358979 + 7.0 + 2.0).epsilon(1e-12));
  const WheelTravel w = SampleMotions(m, 0.4, 20.0);
  // cw: left wheel rolls 8 m + 4 x 0.2 x pi/2, right 8 m - the same.
  CHECK(w.left_m.back() == Approx(8.0 + 0.4 * 3.14159265358979).epsilon(1e-12));
  CHECK(w.right_m.back() == Approx(8.0 - 0.4 * 3.14159265358979).epsilon(1e-12));
}

TEST_CASE("plain least squares: a straight line's scale variance equals the closed form", "[plan]") {
  // No wheel noise, no heading noise: E_s from x_k = E_s s_k with white
  // noise sigma per sample plus the first sample's shift n0 (which moves every
  // residual by -n0): Var = sigma^2 (sum s^2 + (sum s)^2) / (sum s^2)^2.
  WheelTravel w;
  double ss = 0.0, s1 = 0.0;
  for (int k = 0; k <= 50; ++k) {
    const double s = 0.04 * k;
    w.left_m.push_back(s);
    w.right_m.push_back(s);
    if (k > 0) {
      ss += s * s;
      s1 += s;
    }
  }
  GroundTruthModel gt;
  gt.sigma_xy_m = 1e-3;
  gt.sigma_theta_rad = 0.0;
  const LeastSquaresTerms t = PathLeastSquaresTerms(w, {}, 0.4, WheelNoise{0.0, 0.0}, gt);
  CHECK(t.A(0, 0) == Approx(0.0).margin(1e-12));  // a line says nothing about the wheelbase
  CHECK(t.A(2, 2) == Approx(ss).epsilon(1e-6));
  // E_d bends the line: y = (E_d - 1) s^2 / (2 b) (c_R - c_L = E_d - 1 to first order).
  double s4 = 0.0;
  for (int k = 1; k <= 50; ++k) s4 += std::pow(0.04 * k, 4) / (4.0 * 0.16);
  CHECK(t.A(1, 1) == Approx(s4).epsilon(1e-5));
  const double var_closed = 1e-6 * (ss + s1 * s1) / (ss * ss);
  CHECK(t.B(2, 2) / (t.A(2, 2) * t.A(2, 2)) == Approx(var_closed).epsilon(1e-6));
}

TEST_CASE("plain least squares: the sandwich matches a simulation of the noise it models", "[plan]") {
  // Direct simulation, sharing nothing with the suffix sums: the true path
  // integrated with noisy wheel travel per sample interval (variance k^2
  // |travel|), ground truth with white noise, the run's frame at its noisy
  // first sample; the least-squares estimate is A^-1 sum J_k' (g_k - p_k).
  const RobotParams robot = Robot();
  MotionTiming timing;
  const std::vector<Motion> m = RunMotions(RunKind::kSquareCcw, 1.5, {}, robot.wheelbase_m, timing);
  const WheelTravel w = SampleMotions(m, robot.wheelbase_m, 10.0);
  const WheelNoise noise{1.5e-3, 1.0e-3};
  GroundTruthModel gt;
  gt.sigma_xy_m = 5e-4;
  gt.sigma_theta_rad = 3e-3;
  const LeastSquaresTerms t = PathLeastSquaresTerms(w, {}, robot.wheelbase_m, noise, gt);
  const Eigen::Matrix3d predicted = t.Covariance();
  const Eigen::MatrixXd J = OdometryJacobian(w, robot.wheelbase_m);
  const std::vector<Pose2> odo = IntegrateOdometry(w, robot.wheelbase_m, Pose2{});
  const Eigen::Matrix3d Ainv = t.A.inverse();
  std::mt19937_64 rng(20261127);
  std::normal_distribution<double> n01(0.0, 1.0);
  constexpr int kRuns = 4000;
  Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
  const std::size_t n = w.left_m.size();
  for (int r = 0; r < kRuns; ++r) {
    std::vector<Pose2> truth(n);
    for (std::size_t k = 1; k < n; ++k) {
      const double dL = w.left_m[k] - w.left_m[k - 1], dR = w.right_m[k] - w.right_m[k - 1];
      truth[k] = DiffDriveStep(truth[k - 1], dL + noise.k_L * std::sqrt(std::abs(dL)) * n01(rng),
                               dR + noise.k_R * std::sqrt(std::abs(dR)) * n01(rng), robot.wheelbase_m);
    }
    const Pose2 f{gt.sigma_xy_m * n01(rng), gt.sigma_xy_m * n01(rng), gt.sigma_theta_rad * n01(rng)};
    Eigen::Vector3d u = Eigen::Vector3d::Zero();
    for (std::size_t k = 1; k < n; ++k) {
      const double x = truth[k].x + gt.sigma_xy_m * n01(rng) - f.x, y = truth[k].y + gt.sigma_xy_m * n01(rng) - f.y;
      const double gx = std::cos(f.theta) * x + std::sin(f.theta) * y, gy = -std::sin(f.theta) * x + std::cos(f.theta) * y;
      u += J.block<2, 3>(2 * static_cast<Eigen::Index>(k), 0).transpose() * Eigen::Vector2d(gx - odo[k].x, gy - odo[k].y);
    }
    const Eigen::Vector3d d = Ainv * u;
    sum += d * d.transpose();
  }
  const Eigen::Matrix3d mc = sum / kRuns;
  // Variances within 4.5 standard errors of a variance from 4000 draws
  // (sqrt(2/4000) = 2.2 %): 10 %.
  for (int i = 0; i < 3; ++i) {
    INFO("parameter " << i << ": predicted " << predicted(i, i) << ", simulated " << mc(i, i));
    CHECK(mc(i, i) == Approx(predicted(i, i)).epsilon(0.10));
  }
}

TEST_CASE("plan: tape cannot give the scale, mocap can, tighter targets need more runs", "[plan]") {
  PlanOptions o;
  o.robot = Robot();
  o.noise = {1e-3, 1e-3};
  o.ground_truth = GroundTruthKind::kTape;
  o.target_scale = 0.01;
  const PlanResult tape = Plan(o);
  CHECK_FALSE(tape.ok());
  CHECK(tape.unmet.find("never determine the overall scale") != std::string::npos);
  o.ground_truth = GroundTruthKind::kMocap;
  const PlanResult loose = Plan(o);
  REQUIRE(loose.ok());
  REQUIRE(loose.predicted.scale);
  CHECK(*loose.predicted.scale <= 0.01);
  o.target_scale = 2e-4;
  const PlanResult tight = Plan(o);
  REQUIRE(tight.ok());
  CHECK(*tight.predicted.scale <= 2e-4);
  CHECK(tight.design.time_s > loose.design.time_s);
  // The next smaller design (one run fewer per direction) misses the target.
  PlanDesign fewer = tight.design;
  if (fewer.runs_cw > o.min_runs_per_direction) {
    --fewer.runs_cw;
    --fewer.runs_ccw;
    CHECK(*PredictDesign(fewer, o).scale > 2e-4);
  }
}

TEST_CASE("plan: options are checked by field", "[plan]") {
  PlanOptions o;
  o.robot = Robot();
  o.noise = {1e-3, 1e-3};
  CHECK_THROWS_WITH(Plan(o), Catch::Contains("no target"));
  o.target_k = 1e-4;
  o.noise = {0.0, 1e-3};
  CHECK_THROWS_WITH(Plan(o), Catch::Contains("target_k needs"));
  o.noise = {1e-3, 1e-3};
  o.max_side_m = 0.1;
  CHECK_THROWS_WITH(Plan(o), Catch::Contains("max_side_m"));
}

TEST_CASE("advice: record_more is the closed form of classic UMBmark's 1/n covariance", "[plan][advice]") {
  // Endpoint (tape) squares: classic UMBmark's covariance is G diag(C_cw /
  // n_cw, C_ccw / n_ccw) G', so with n runs per direction its half-width
  // is h(n) = h(3) sqrt(3 / n) exactly. The runs needed to bring E_d's to
  // half of a 0.05 % correction follow in closed form.
  CalibrateInput in;
  in.label = in.path = "squares.csv";
  in.recorded = Robot();
  in.side_m = 1.0;
  for (int i = 0; i < 6; ++i)  // the values do not enter: the noise is given
    in.errors.push_back(ReturnError{std::to_string(i + 1), i % 2 ? "ccw" : "cw", 0.01 * i, -0.004 * i, 0.002, 0, {}});
  RobotParams cal = in.recorded;
  cal.wheel_diameter_right_m *= 1.0005;  // E_d = 1.0005
  cal.wheelbase_m *= 1.02;               // E_b = 1.02: well determined
  const DesignAdvice a = AdviseCalibration(in, cal, WheelNoise{1e-3, 1e-3}, GroundTruthModel{false, 2e-3, 5e-3});
  INFO(a.note);
  REQUIRE(a.available);
  CHECK(a.check.method == "umbmark_mean");
  REQUIRE(a.check.predicted.E_d);
  const double h3 = *a.check.predicted.E_d, target = 0.5 * 0.0005;
  REQUIRE(h3 > target);
  REQUIRE(a.check.record_more.size() == 1);  // E_b's 2 % is determined
  const RecordMore& m = a.check.record_more.front();
  CHECK(m.quantity == "E_d");
  CHECK(m.correction == Approx(0.0005).epsilon(1e-9));
  CHECK(m.half_width == Approx(h3).epsilon(1e-12));
  const int expected = static_cast<int>(std::ceil(3.0 * (h3 / target) * (h3 / target) - 1e-9)) - 3;
  CHECK(m.extra_runs_per_direction == expected);
  CHECK(m.half_width_after == Approx(h3 * std::sqrt(3.0 / (3.0 + expected))).epsilon(1e-6));
  CHECK(m.half_width_after <= target);
  REQUIRE(a.messages.size() == 1);
  CHECK(a.messages.front().find(fmt::format("record {} more square run(s) of 1.00 m", expected)) != std::string::npos);
  // A correction no practical design determines: the message says to keep the recorded value.
  cal.wheel_diameter_right_m = in.recorded.wheel_diameter_right_m * 1.000001;
  const DesignAdvice tiny = AdviseCalibration(in, cal, WheelNoise{1e-3, 1e-3}, GroundTruthModel{false, 2e-3, 5e-3});
  REQUIRE(tiny.check.record_more.size() == 1);
  CHECK(tiny.check.record_more.front().extra_runs_per_direction == 0);
  CHECK(tiny.messages.front().find("keep the recorded value") != std::string::npos);
  // Its driving time in the unit a person reads: hours past 1.5 h, minutes past 2 min.
  const double t = tiny.check.record_more.front().time_s;
  const std::string when = t >= 5400.0 ? fmt::format("even {:.1f} h more of driving", t / 3600.0)
                           : t >= 120.0 ? fmt::format("even {:.0f} min more of driving", t / 60.0)
                                        : fmt::format("even {:.0f} s more of driving", t);
  CHECK(tiny.messages.front().find(when) != std::string::npos);
  // The recorded parameters (no correction): nothing to determine.
  CHECK(AdviseCalibration(in, in.recorded, WheelNoise{1e-3, 1e-3}).check.record_more.empty());
}

TEST_CASE("advice: never throws; what it cannot analyse is a note", "[plan][advice]") {
  CalibrateInput in;
  in.label = in.path = "cw_only.csv";
  in.recorded = Robot();
  in.side_m = 1.0;
  const DesignAdvice none = AdviseCalibration(in, in.recorded);  // no runs at all
  CHECK_FALSE(none.available);
  CHECK(none.note.find("no square run") != std::string::npos);
  CHECK(none.messages.empty());
}
