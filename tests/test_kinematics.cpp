// Differential-drive kinematics: the exact-arc step against the closed-form
// circle, its safety at and near straight motion, the midpoint step's
// discretisation error, SE(2) helpers, and odometry along a logged run.
#include <catch2/catch.hpp>

#include <ceres/jet.h>

#include <cmath>

#include "core/angles.hpp"
#include "kinematics/diff_drive.hpp"
#include "kinematics/odometry.hpp"

using namespace umbmark;

TEST_CASE("Arc step equals the closed-form circle", "[kinematics]") {
  const double b = 0.34;
  for (auto [dl, dr] : {std::pair{1.0, 1.2}, {0.3, -0.3}, {-0.5, -0.45}, {0.0, 0.7}, {2.0, 1.0}}) {
    const Pose2 start{0.3, -0.2, 0.7};
    const Pose2 p = DiffDriveStep(start, dl, dr, b, Integrator::kArc);
    const double dth = (dr - dl) / b, ds = 0.5 * (dl + dr);
    const double r = ds / dth;  // signed radius
    CHECK(p.x == Approx(start.x + r * (std::sin(start.theta + dth) - std::sin(start.theta))).epsilon(1e-13));
    CHECK(p.y == Approx(start.y - r * (std::cos(start.theta + dth) - std::cos(start.theta))).epsilon(1e-13));
    CHECK(p.theta == Approx(start.theta + dth).epsilon(1e-15));
  }
}

TEST_CASE("Arc step is exact under subdivision and safe near straight motion", "[kinematics]") {
  // Splitting a constant-curvature step into many gives the same pose.
  const double b = 0.2;
  for (double dr : {1.0 + 1e-3, 1.0 + 1e-7, 1.0 + 1e-12, 1.0, 1.0 - 2e-5}) {
    const double dl = 1.0;
    const Pose2 one = DiffDriveStep(Pose2{}, dl, dr, b);
    Pose2 many;
    for (int i = 0; i < 1000; ++i) many = DiffDriveStep(many, dl / 1000, dr / 1000, b);
    INFO("dr = " << dr);
    CHECK(one.x == Approx(many.x).epsilon(1e-12));
    CHECK(one.y == Approx(many.y).margin(1e-14));
    CHECK(std::isfinite(one.x));
  }
  // The series branch and the sin(u)/u branch agree at the seam.
  const double u = 1e-4;
  CHECK(Sinc(u * (1 - 1e-12)) == Approx(std::sin(u) / u).epsilon(1e-16));
  CHECK(Sinc(0.0) == 1.0);
}

TEST_CASE("Midpoint step error is O(ds dtheta^2 / 24)", "[kinematics]") {
  const double b = 0.3, dl = 0.1, dr = 0.13;
  const Pose2 arc = DiffDriveStep(Pose2{}, dl, dr, b, Integrator::kArc);
  const Pose2 mid = DiffDriveStep(Pose2{}, dl, dr, b, Integrator::kMidpoint);
  const double ds = 0.5 * (dl + dr), dth = (dr - dl) / b;
  const double chord_err = std::hypot(arc.x - mid.x, arc.y - mid.y);
  CHECK(chord_err == Approx(ds * (1 - std::sin(dth / 2) / (dth / 2))).epsilon(1e-9));
  CHECK(chord_err == Approx(ds * dth * dth / 24).epsilon(2e-3));
  CHECK(arc.theta == mid.theta);
}

TEST_CASE("Arc step works with ceres::Jet and gives the right derivative", "[kinematics]") {
  using J = ceres::Jet<double, 1>;
  const double dl = 0.5, dr = 0.52, b0 = 0.25;
  const J b(b0, 0);
  const auto p = DiffDriveStep(Pose2T<J>{}, J(dl), J(dr), b);
  const double h = 1e-7;
  const Pose2 plus = DiffDriveStep(Pose2{}, dl, dr, b0 + h), minus = DiffDriveStep(Pose2{}, dl, dr, b0 - h);
  CHECK(p.y.v[0] == Approx((plus.y - minus.y) / (2 * h)).epsilon(1e-6));
  CHECK(p.theta.v[0] == Approx(-(dr - dl) / (b0 * b0)).epsilon(1e-12));
}

TEST_CASE("SE(2) compose, inverse and wrap", "[kinematics]") {
  const Pose2 a{1.0, 2.0, 0.5}, b{-0.3, 0.4, -1.2};
  const Pose2 id = Compose(a, Inverse(a));
  CHECK(id.x == Approx(0).margin(1e-15));
  CHECK(id.y == Approx(0).margin(1e-15));
  const Pose2 rel = RelativeTo(a, Compose(a, b));
  CHECK(rel.x == Approx(b.x).epsilon(1e-14));
  CHECK(rel.y == Approx(b.y).epsilon(1e-14));
  CHECK(rel.theta == Approx(b.theta).epsilon(1e-14));
  CHECK(WrapAngle(kPi) == Approx(kPi));
  CHECK(WrapAngle(-kPi) == Approx(kPi));
  CHECK(WrapAngle(3 * kPi + 0.1) == Approx(-kPi + 0.1));
  CHECK(WrapAngle(-2 * kPi + 0.2) == Approx(0.2));
}

TEST_CASE("Odometry from cumulative ticks along a run", "[kinematics]") {
  RobotParams robot{0.2, 0.08, 0.1, 1000.0};
  TrajectoryRun run;
  // Straight then a spot turn of +90 deg (ccw): right wheel +, left wheel -.
  const double per_tick_l = kPi * 0.08 / 1000, per_tick_r = kPi * 0.1 / 1000;
  const auto ticks_for = [](double metres, double per_tick) { return static_cast<std::int64_t>(std::llround(metres / per_tick)); };
  run.t_s = {0, 1, 2};
  run.ticks_left = {100, 100 + ticks_for(1.0, per_tick_l), 100 + ticks_for(1.0, per_tick_l) - ticks_for(0.05 * kPi, per_tick_l)};
  run.ticks_right = {-5, -5 + ticks_for(1.0, per_tick_r), -5 + ticks_for(1.0, per_tick_r) + ticks_for(0.05 * kPi, per_tick_r)};
  const auto travel = ComputeWheelTravel(run, robot, robot);
  CHECK(travel.left_m[0] == 0.0);
  CHECK(travel.right_m[1] == Approx(1.0).margin(per_tick_r));
  const auto poses = IntegrateOdometry(travel, robot.wheelbase_m, Pose2{});
  CHECK(poses[1].x == Approx(1.0).margin(2e-4));
  CHECK(poses[2].theta == Approx(kPi / 2).margin(2e-3));
  CHECK(poses[2].x == Approx(poses[1].x).margin(1e-6));  // a spot turn does not move the centre
}
