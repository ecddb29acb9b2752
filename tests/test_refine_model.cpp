// Building blocks of the refined calibration, each against an independent
// reference: the exact commanded-square model (closed-form polygon, fine-step
// integration, Borenstein & Feng's first-order formulas through the classic
// UMBmark code), the residuals' automatic Jacobians (central differences),
// the per-pose robust reweighting (Ceres' own loss functions) and the t and
// normal quantiles (closed forms and tables).
//
// Ceres' autodiff and loss headers pull in glog, whose CHECK macro would
// replace Catch's: include them first and drop glog's CHECK.
#include <ceres/loss_function.h>

#include "calibration/refine_residuals.hpp"
#undef CHECK

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <vector>

#include "stats/distributions.hpp"
#include "calibration/umbmark.hpp"
#include "core/angles.hpp"
#include "model/commanded_square.hpp"

using namespace umbmark;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

constexpr double kB = 0.34;  // recorded wheelbase [m]

// Independent reference: integrates each motion's true wheel travels in
// `steps` midpoint steps (second-order, error O(step^2)).
Pose2 FineStep(const std::vector<CommandedMotion>& motions, double E_b, double c_L, double c_R, int steps) {
  Pose2 p;
  for (const auto& m : motions) {
    const double dl = c_L * m.nominal_left_m / steps, dr = c_R * m.nominal_right_m / steps;
    for (int i = 0; i < steps; ++i) p = DiffDriveStep(p, dl, dr, E_b * kB, Integrator::kMidpoint);
  }
  return p;
}

}  // namespace

TEST_CASE("commanded square: motions and the odometry's own final pose", "[refine][model]") {
  for (bool final_turn : {true, false}) {
    for (SquareDirection dir : {SquareDirection::kCw, SquareDirection::kCcw}) {
      const auto motions = CommandedSquare(dir, 4.0, kB, final_turn);
      REQUIRE(motions.size() == (final_turn ? 8u : 7u));
      const Pose2 odo = OdometryOfCommanded(motions, kB);
      CHECK_THAT(odo.x, WithinAbs(0.0, 1e-12));
      CHECK_THAT(odo.y, WithinAbs(0.0, 1e-12));
      const double turns = final_turn ? 4.0 : 3.0;
      CHECK_THAT(odo.theta, WithinAbs((dir == SquareDirection::kCw ? -1.0 : 1.0) * turns * kPi / 2.0, 1e-12));
    }
  }
  CHECK(SquareDirectionFromString("cw") == SquareDirection::kCw);
  CHECK(SquareDirectionFromString("ccw") == SquareDirection::kCcw);
  CHECK_FALSE(SquareDirectionFromString("CW").has_value());
  CHECK(std::string(SquareDirectionToString(SquareDirection::kCcw)) == "ccw");
}

TEST_CASE("commanded square: a pure wheelbase error gives the closed-form polygon", "[refine][model]") {
  // Equal wheels, E_b only: legs are straight, every turn is (pi/2)/E_b, so
  // the true path is the polygon sum_k L (cos k phi, sin k phi).
  const double L = 3.0;
  for (double E_b : {0.9, 0.99, 1.05}) {
    for (SquareDirection dir : {SquareDirection::kCw, SquareDirection::kCcw}) {
      const double phi = (dir == SquareDirection::kCw ? -1.0 : 1.0) * (kPi / 2.0) / E_b;
      double x = 0.0, y = 0.0;
      for (int k = 0; k < 4; ++k) {
        x += L * std::cos(k * phi);
        y += L * std::sin(k * phi);
      }
      const Pose2 e = SquareReturnError(dir, L, kB, E_b, 1.0, 1.0);
      CHECK_THAT(e.x, WithinAbs(x, 1e-12));
      CHECK_THAT(e.y, WithinAbs(y, 1e-12));
      CHECK_THAT(e.theta, WithinAbs(4.0 * phi - (dir == SquareDirection::kCw ? -2.0 : 2.0) * kPi, 1e-12));
    }
  }
}

TEST_CASE("commanded square: exact arcs equal fine-step integration", "[refine][model]") {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.9, 1.1);
  for (int trial = 0; trial < 5; ++trial) {
    const double E_b = u(rng), c_L = u(rng), c_R = u(rng);
    for (SquareDirection dir : {SquareDirection::kCw, SquareDirection::kCcw}) {
      const auto motions = CommandedSquare(dir, 2.5, kB);
      const Pose2 exact = ExecuteCommanded(motions, kB, E_b, c_L, c_R);
      const Pose2 fine = FineStep(motions, E_b, c_L, c_R, 20000);
      // Midpoint error per motion ~ L dtheta^2 / (24 steps^2) < 1e-9 m here
      // (dtheta up to 1.5 rad per leg with these factors).
      CHECK_THAT(exact.x, WithinAbs(fine.x, 1e-8));
      CHECK_THAT(exact.y, WithinAbs(fine.y, 1e-8));
      CHECK_THAT(exact.theta, WithinAbs(fine.theta, 1e-10));  // rounding over 1.6e5 steps
    }
  }
}

TEST_CASE("commanded square: first order agrees with classic UMBmark (Borenstein & Feng sec. 4)", "[refine][model]") {
  // For small errors the classic (linearised) estimator applied to the exact
  // model's return errors must give back E_b and E_d up to second-order
  // terms: this pins the sign conventions of both implementations together.
  const RobotParams rec{kB, 0.1524, 0.1524, std::nullopt};
  const double L = 4.0;
  for (auto [E_b, E_d] : {std::pair{1.0005, 1.0002}, std::pair{0.9995, 0.9998}, std::pair{1.0003, 0.9997}}) {
    const double c_L = 2.0 / (E_d + 1.0), c_R = 2.0 * E_d / (E_d + 1.0);
    std::vector<ReturnError> errors;
    for (SquareDirection dir : {SquareDirection::kCw, SquareDirection::kCcw}) {
      const Pose2 e = SquareReturnError(dir, L, kB, E_b, c_L, c_R);
      ReturnError r;
      r.run = SquareDirectionToString(dir);
      r.direction = r.run;
      r.ex_m = e.x;
      r.ey_m = e.y;
      r.etheta_rad = e.theta;
      errors.push_back(r);
    }
    UmbmarkOptions o;
    o.side_m = L;
    const UmbmarkSummary s = CalibrateUmbmark(errors, rec, o);
    // Errors are ~5e-4, so second-order terms are ~1e-6 relative.
    CHECK_THAT(s.selected.E_b, WithinRel(E_b, 5e-6));
    CHECK_THAT(s.selected.E_d, WithinRel(E_d, 5e-6));
  }
}

TEST_CASE("square return-error residual: autodiff Jacobian equals central differences", "[refine][jacobian]") {
  for (SquareDirection dir : {SquareDirection::kCw, SquareDirection::kCcw}) {
    Eigen::MatrixXd sqrt_info(3, 3);
    sqrt_info << 50.0, 0.0, 0.0, 3.0, 40.0, 0.0, -2.0, 5.0, 200.0;
    Eigen::VectorXd measured(3);
    measured << 0.1, -0.2, 0.05;
    std::unique_ptr<ceres::CostFunction> cost(SquareReturnErrorResidual::Create(
        CommandedSquare(dir, 3.0, kB), kB, Eigen::Vector3d(1.01, 0.99, 1.02), measured, sqrt_info));
    double theta[3] = {0.93, 1.015, 1.004};
    const double* params[] = {theta};
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> J;
    double* jac[] = {J.data()};
    Eigen::Vector3d r;
    REQUIRE(cost->Evaluate(params, r.data(), jac));
    for (int k = 0; k < 3; ++k) {
      const double h = 1e-6;
      double tp[3] = {theta[0], theta[1], theta[2]}, tm[3] = {theta[0], theta[1], theta[2]};
      tp[k] += h;
      tm[k] -= h;
      const double* pp[] = {tp};
      const double* pm[] = {tm};
      Eigen::Vector3d rp, rm;
      REQUIRE(cost->Evaluate(pp, rp.data(), nullptr));
      REQUIRE(cost->Evaluate(pm, rm.data(), nullptr));
      const Eigen::Vector3d numeric = (rp - rm) / (2.0 * h);
      for (int i = 0; i < 3; ++i) CHECK_THAT(J(i, k), WithinAbs(numeric(i), 1e-6 * (1.0 + std::abs(numeric(i)))));
    }
  }
}

TEST_CASE("trajectory residual: autodiff Jacobian equals central differences, with each loss", "[refine][jacobian]") {
  // A wiggly path with ground truth off the odometry, so losses are active.
  std::vector<double> dl, dr;
  std::vector<TrajectoryRunResidual::Sample> samples;
  Pose2 truth;
  for (int i = 0; i < 400; ++i) {
    const double a = 0.01 + 0.004 * std::sin(0.05 * i), b = 0.01 + 0.004 * std::cos(0.03 * i);
    dl.push_back(a);
    dr.push_back(b);
    truth = DiffDriveStep(truth, 1.01 * a, 0.98 * b, 0.95 * kB);
    if ((i + 1) % 40 == 0) samples.push_back({static_cast<std::size_t>(i + 1), truth});
  }
  for (RobustLoss loss : {RobustLoss::kNone, RobustLoss::kHuber, RobustLoss::kCauchy}) {
    std::unique_ptr<ceres::CostFunction> cost(
        TrajectoryRunResidual::Create(dl, dr, kB, samples, kB, loss, 0.01, Integrator::kArc));
    const int m = cost->num_residuals();
    REQUIRE(m == 3 * static_cast<int>(samples.size()));
    double theta[3] = {1.02, 0.99, 1.01};
    const double* params[] = {theta};
    Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> J(m, 3);
    double* jac[] = {J.data()};
    Eigen::VectorXd r(m);
    REQUIRE(cost->Evaluate(params, r.data(), jac));
    for (int k = 0; k < 3; ++k) {
      const double h = 1e-6;
      double tp[3] = {theta[0], theta[1], theta[2]}, tm[3] = {theta[0], theta[1], theta[2]};
      tp[k] += h;
      tm[k] -= h;
      const double* pp[] = {tp};
      const double* pm[] = {tm};
      Eigen::VectorXd rp(m), rm(m);
      REQUIRE(cost->Evaluate(pp, rp.data(), nullptr));
      REQUIRE(cost->Evaluate(pm, rm.data(), nullptr));
      const Eigen::VectorXd numeric = (rp - rm) / (2.0 * h);
      for (int i = 0; i < m; ++i) {
        INFO("loss " << RobustLossToString(loss) << " residual " << i << " parameter " << k);
        CHECK_THAT(J(i, k), WithinAbs(numeric(i), 1e-6 * (1.0 + std::abs(numeric(i)))));
      }
    }
  }
}

TEST_CASE("per-pose robust factor reproduces Ceres' loss functions", "[refine][loss]") {
  const double a = 0.02;
  ceres::HuberLoss huber(a);
  ceres::CauchyLoss cauchy(a);
  for (double s : {0.0, 1e-12, 1e-6, 3.9e-4, 4.0e-4, 4.1e-4, 1e-2, 1.0}) {
    double rho[3];
    huber.Evaluate(s, rho);
    const double fh = RobustFactor(s, RobustLoss::kHuber, a);
    CHECK_THAT(fh * fh * s, WithinAbs(rho[0], 1e-15 + 1e-12 * rho[0]));
    cauchy.Evaluate(s, rho);
    const double fc = RobustFactor(s, RobustLoss::kCauchy, a);
    CHECK_THAT(fc * fc * s, WithinAbs(rho[0], 1e-15 + 1e-12 * rho[0]));
    CHECK(RobustFactor(s, RobustLoss::kNone, a) == 1.0);
  }
  CHECK(RobustLossFromString("huber") == RobustLoss::kHuber);
  CHECK(RobustLossFromString("cauchy") == RobustLoss::kCauchy);
  CHECK(RobustLossFromString("none") == RobustLoss::kNone);
  CHECK_FALSE(RobustLossFromString("l1").has_value());
}

TEST_CASE("normal and Student t quantiles", "[refine][stats]") {
  CHECK_THAT(NormalQuantile(0.975), WithinAbs(1.959963984540054, 1e-12));
  CHECK_THAT(NormalQuantile(0.5), WithinAbs(0.0, 1e-14));
  CHECK_THAT(NormalQuantile(0.025), WithinAbs(-1.959963984540054, 1e-12));
  // dof 1 is the Cauchy distribution: t = tan(pi (p - 1/2)).
  CHECK_THAT(StudentTQuantile(0.975, 1.0), WithinRel(std::tan(kPi * 0.475), 1e-10));
  // dof 2: t = (2p - 1) / sqrt(2 p (1 - p)).
  CHECK_THAT(StudentTQuantile(0.975, 2.0), WithinRel(0.95 / std::sqrt(2.0 * 0.975 * 0.025), 1e-10));
  // Tables: t_{0.975}(10) = 2.228139, t_{0.975}(30) = 2.042272.
  CHECK_THAT(StudentTQuantile(0.975, 10.0), WithinAbs(2.228139, 1e-6));
  CHECK_THAT(StudentTQuantile(0.975, 30.0), WithinAbs(2.042272, 1e-6));
  CHECK_THAT(StudentTQuantile(0.975, 1e7), WithinAbs(1.959963984540054, 1e-6));
  CHECK(std::isnan(StudentTQuantile(1.0, 3.0)));
  CHECK(std::isnan(NormalQuantile(0.0)));
}
