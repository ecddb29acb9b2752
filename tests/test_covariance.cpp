// Closed-form covariance of Chong & Kleeman (eqs. 17, 21, 23, 25-28) and
// Kelly's trajectory form, each checked against an independent numerical
// reference: many-segment propagation of the exact step Jacobians obtained
// by automatic differentiation (error_models/numerical_propagation.hpp).
//
// "1e-9 relative" for a covariance means, element by element,
//   |C_ij - ref_ij| <= 1e-9 * sqrt(ref_ii * ref_jj)
// (relative to the scale of that element, so a cross term that is exactly
// zero is held to the same standard as the variances it couples).
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "core/angles.hpp"
#include "error_models/arc_jacobians.hpp"
#include "error_models/covariance_arc.hpp"
#include "error_models/covariance_line.hpp"
#include "error_models/covariance_turn.hpp"
#include "error_models/numerical_propagation.hpp"
#include "error_models/path_covariance.hpp"
#include "error_models/trajectory_covariance.hpp"

using namespace umbmark;

namespace {

/// Largest element error in units of sqrt(ref_ii ref_jj).
double ScaledError(const PoseCovariance& c, const PoseCovariance& ref) {
  double worst = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double scale = std::sqrt(ref(i, i) * ref(j, j));
      worst = std::max(worst, std::abs(c(i, j) - ref(i, j)) / scale);
    }
  return worst;
}

double BasisError(const CovarianceBasis& c, const CovarianceBasis& ref) {
  return std::max(ScaledError(c.A_L, ref.A_L), ScaledError(c.A_R, ref.A_R));
}

/// Reference for a single segment starting at heading theta0: a zero-length
/// turn first rotates the frame (a spot turn of 0 wheel travel is not
/// possible), so we rotate the result instead: Cov at heading theta0 is
/// Rot * Cov(heading 0) * Rot^T for the x-y block.
CovarianceBasis ReferenceSegment(double L, double R, double theta0, double B) {
  const CovarianceBasis b0 = NumericalPathCovarianceBasis({{L, R}}, B);
  Eigen::Matrix3d rot = Eigen::Matrix3d::Identity();
  rot(0, 0) = std::cos(theta0);
  rot(0, 1) = -std::sin(theta0);
  rot(1, 0) = std::sin(theta0);
  rot(1, 1) = std::cos(theta0);
  CovarianceBasis b;
  b.A_L = rot * b0.A_L * rot.transpose();
  b.A_R = rot * b0.A_R * rot.transpose();
  return b;
}

struct ArcCase {
  const char* name;
  double L, R, theta0;
};

}  // namespace

TEST_CASE("eq. 17 corrected equals the automatic-differentiation Jacobian; the printed one does not", "[covariance]") {
  using Jet = ceres::Jet<double, 5>;
  const double B = 0.4;
  for (const auto& c : std::vector<ArcCase>{{"left", 0.3, 0.5, 0.2}, {"right", 0.5, 0.1, -1.0}, {"rev", -0.4, -0.1, 2.0}}) {
    const Pose2T<Jet> p{Jet(0.0, 0), Jet(0.0, 1), Jet(c.theta0, 2)};
    const Pose2T<Jet> q = DiffDriveStep(p, Jet(c.L, 3), Jet(c.R, 4), Jet(B));
    const Eigen::Matrix<double, 3, 2> J = ArcStepWheelJacobian(c.theta0, c.L, c.R, B);
    const Jet* rows[3] = {&q.x, &q.y, &q.theta};
    for (int a = 0; a < 3; ++a)
      for (int w = 0; w < 2; ++w) CHECK(J(a, w) == Approx(rows[a]->v[3 + w]).margin(1e-13));
    // State Jacobian, eq. 16 (= eq. 21 for one step).
    const Eigen::Matrix3d F = StepStateJacobian({0.0, 0.0, c.theta0}, {q.x.a, q.y.a, q.theta.a});
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) CHECK(F(a, b) == Approx(rows[a]->v[b]).margin(1e-13));

    // Evidence for the misprints: as printed, eq. 17 has r_k instead of r_k/B
    // in rows 1-2 and -B L/(L-R)^2 in row 2, column 2.
    const double thk = c.theta0 + (c.R - c.L) / B;
    const double r = 0.5 * B * (c.L + c.R) / (c.L - c.R);
    const double d2 = (c.L - c.R) * (c.L - c.R);
    const double printed_00 = -B * c.R / d2 * (std::sin(c.theta0) - std::sin(thk)) + r * std::cos(thk);
    const double printed_11 = -B * c.L / d2 * (std::cos(thk) - std::cos(c.theta0)) - r * std::sin(thk);
    CHECK(std::abs(printed_00 - q.x.v[3]) > 1e-3);
    CHECK(std::abs(printed_11 - q.y.v[4]) > 1e-3);
  }
}

TEST_CASE("numerical reference converges (Richardson levels agree)", "[covariance]") {
  const std::vector<WheelSegment> path{{3.0, 1.0}};
  NumericalPropagationOptions coarse;
  coarse.steps_per_segment = 1024;
  const CovarianceBasis a = NumericalPathCovarianceBasis(path, 0.4, PoseCovariance::Zero(), nullptr, coarse);
  const CovarianceBasis b = NumericalPathCovarianceBasis(path, 0.4);
  CHECK(BasisError(a, b) < 1e-11);
  // Without extrapolation the plain propagation is visibly first-order off.
  NumericalPropagationOptions plain;
  plain.richardson_levels = 1;
  plain.steps_per_segment = 1024;
  const CovarianceBasis c = NumericalPathCovarianceBasis(path, 0.4, PoseCovariance::Zero(), nullptr, plain);
  CHECK(BasisError(c, b) > 1e-8);
}

TEST_CASE("eq. 25 (arc) matches numerical propagation to 1e-9", "[covariance]") {
  const double B = 0.4;
  const std::vector<ArcCase> cases{
      {"Table 1 arc", 3.0, 1.0, 0.0},
      {"Table 2 arc", 15.0, 10.0, 0.0},
      {"left turn, heading 1.1", 1.0, 2.5, 1.1},
      {"reversing", -2.0, -0.7, -0.4},
      {"mixed sign", -0.5, 1.5, 0.3},
      {"mixed sign, mostly left", 1.2, -0.2, 2.9},
      {"pivot on left wheel", 0.0, 1.3, 0.0},
      {"pivot on right wheel", 0.9, 0.0, -2.0},
      {"pivot backwards", 0.0, -0.8, 0.5},
      {"several turns", 1.0, 8.0, 0.0},
  };
  for (const ArcCase& c : cases) {
    INFO(c.name);
    const CovarianceBasis ref = ReferenceSegment(c.L, c.R, c.theta0, B);
    CHECK(BasisError(ArcCovarianceBasisClosedForm(c.L, c.R, c.theta0, B), ref) < 1e-9);
    CHECK(BasisError(ArcCovarianceBasis(c.L, c.R, c.theta0, B), ref) < 1e-9);
  }
}

TEST_CASE("nearly straight arcs: quadrature below the threshold, seam is continuous", "[covariance]") {
  const double B = 0.371;
  // Both sides of the seam and well inside the quadrature region.
  for (double dth : {kArcQuadratureBelowRad * 1.001, kArcQuadratureBelowRad * 0.999, 0.05, 1e-3, 1e-6, 0.0}) {
    INFO("dtheta = " << dth);
    const double L = 5.0, R = L + dth * B;
    const CovarianceBasis ref = ReferenceSegment(L, R, 0.7, B);
    CHECK(BasisError(ArcCovarianceBasis(L, R, 0.7, B), ref) < 1e-9);
    CHECK(BasisError(ArcCovarianceBasisQuadrature(L, R, 0.7, B), ref) < 1e-9);
  }
  // At the seam both methods agree far better than the tolerance.
  const double R = 5.0 + kArcQuadratureBelowRad * B;
  CHECK(BasisError(ArcCovarianceBasisClosedForm(5.0, R, 0.7, B), ArcCovarianceBasisQuadrature(5.0, R, 0.7, B)) < 1e-12);
  // Why the seam exists: eq. 25 cancels catastrophically near straight lines.
  const double Rs = 5.0 + 1e-5 * B;
  CHECK(BasisError(ArcCovarianceBasisClosedForm(5.0, Rs, 0.7, B), ReferenceSegment(5.0, Rs, 0.7, B)) > 1e-6);
}

TEST_CASE("eq. 26 (line, corrected) and eq. 27 match numerical propagation", "[covariance]") {
  const double B = 0.371;
  for (double D : {10.0, -10.0, 0.5}) {
    for (double theta : {0.0, 0.6, -2.3, kPi / 2}) {
      INFO("D = " << D << " theta = " << theta);
      const CovarianceBasis ref = ReferenceSegment(D, D, theta, B);
      const CovarianceBasis line = LineCovarianceBasis(D, theta, B);
      CHECK(BasisError(line, ref) < 1e-9);
      // Evidence for the misprint: eq. 26 as printed has sin^2 in Cov(U)_22.
      if (std::abs(std::cos(theta)) > 0.1) {
        const double printed_22 = std::abs(D) * (0.25 * std::pow(std::sin(theta), 2) -
                                                 D / (2 * B) * std::sin(theta) * std::cos(theta) +
                                                 D * D / (3 * B * B) * std::pow(std::sin(theta), 2));
        CHECK(std::abs(printed_22 - ref.A_L(1, 1)) > 1e-3 * ref.A_L(1, 1));
      }
    }
  }
  const WheelNoise n{0.0004, 0.00058};
  const PoseCovariance eq27 = LineCovarianceAlongX(10.0, B, n);
  CHECK(ScaledError(eq27, LineCovarianceBasis(10.0, 0.0, B).Evaluate(n)) < 1e-14);
  // Correlation of y and theta quoted after eq. 27: sqrt(3)/2 = 0.866.
  CHECK(eq27(1, 2) / std::sqrt(eq27(1, 1) * eq27(2, 2)) == Approx(std::sqrt(3.0) / 2.0).epsilon(1e-12));
}

TEST_CASE("eq. 28 (spot turn) matches numerical propagation; the printed limits are swapped", "[covariance]") {
  const double B = 0.4;
  for (double phi : {kPi / 2, -kPi / 2, 5.0, -0.3}) {
    for (double theta0 : {0.0, 1.0, -2.5}) {
      INFO("phi = " << phi << " theta0 = " << theta0);
      const double L = -0.5 * B * phi, R = 0.5 * B * phi;  // correct limits
      const CovarianceBasis ref = ReferenceSegment(L, R, theta0, B);
      const CovarianceBasis turn = TurnCovarianceBasis(phi, theta0, B);
      CHECK(BasisError(turn, ref) < 1e-9);
      CHECK(BasisError(ArcCovarianceBasisClosedForm(L, R, theta0, B), ref) < 1e-9);
      // The printed limits L -> (B/2)(th_k - th_0), R -> (B/2)(th_0 - th_k)
      // turn the robot by -phi, so they cannot be what eq. 28 describes.
      const Pose2 end = DiffDriveStep(Pose2{0.0, 0.0, theta0}, 0.5 * B * phi, -0.5 * B * phi, B);
      CHECK(end.theta - theta0 == Approx(-phi).epsilon(1e-12));
      // The swapped wheels give a different y-theta term (int sin(theta) is odd in phi).
      const CovarianceBasis swapped = ReferenceSegment(0.5 * B * phi, -0.5 * B * phi, theta0, B);
      if (std::abs(ref.A_L(1, 2)) > 1e-3) CHECK(std::abs(swapped.A_L(1, 2) - ref.A_L(1, 2)) > 1e-4);
    }
  }
}

TEST_CASE("eq. 23 composition over segments with non-zero P0", "[covariance]") {
  const double B = 0.371;
  const WheelNoise n{0.00040, 0.00058};
  PoseCovariance P0;
  P0 << 0.0025, 0.0004, -0.001, 0.0004, 0.0016, 0.0008, -0.001, 0.0008, 0.0012;
  const std::vector<std::vector<WheelSegment>> paths{
      {{10.0, 10.0}, {-10.0, -10.0}},                                       // back and forth
      {{4.0, 4.0}, {0.2914, -0.2914}, {4.0, 4.0}, {0.2914, -0.2914}},        // square-ish, cw turns
      {{1.0, 2.0}, {-0.5, 0.7}, {0.0, 1.0}, {-2.0, -2.0}, {3.0, 2.999999}},  // mixed, nearly-straight arc
  };
  for (const auto& path : paths) {
    PoseCovariance ref_p0;
    const CovarianceBasis ref = NumericalPathCovarianceBasis(path, B, P0, &ref_p0);
    const PathCovarianceSummary s = PredictPathCovariance(path, B, n, P0);
    CHECK(BasisError(s.motion, ref) < 1e-9);
    // The reference transports P0 through ~25000 steps: rounding ~1e-12.
    CHECK(ScaledError(s.initial_term, ref_p0) < 1e-10);
    CHECK(ScaledError(s.covariance, ref_p0 + ref.Evaluate(n)) < 1e-9);
  }
}

TEST_CASE("predict line:10,line:-10 with Chong's constants matches numerical propagation", "[covariance]") {
  const double B = 0.371;
  const WheelNoise n{0.00040, 0.00058};
  const auto path = ToWheelSegments(ParsePathSpec("line:10,line:-10"), B);
  const PathCovarianceSummary s = PredictPathCovariance(path, B, n, PoseCovariance::Zero());
  const PoseCovariance ref = NumericalPathCovarianceBasis(path, B).Evaluate(n);
  CHECK(ScaledError(s.covariance, ref) < 1e-9);
  CHECK(std::abs(s.mean.x) < 1e-12);
  CHECK(std::abs(s.mean.y) < 1e-12);
  // Independent sanity: the heading variance is exactly (k_L^2 + k_R^2) 20 / B^2.
  CHECK(s.covariance(2, 2) == Approx((n.k_L * n.k_L + n.k_R * n.k_R) * 20.0 / (B * B)).epsilon(1e-13));
}

TEST_CASE("Kelly's trajectory form equals segment composition on a sampled path", "[covariance]") {
  const double B = 0.371;
  const std::vector<WheelSegment> path{{2.0, 2.0}, {-0.3, 0.3}, {1.0, 1.7}, {-1.5, -1.5}};
  // Sample each segment at 50 points (cumulative wheel travel).
  WheelTravel travel;
  travel.left_m.push_back(0.0);
  travel.right_m.push_back(0.0);
  for (const auto& s : path)
    for (int i = 1; i <= 50; ++i) {
      travel.left_m.push_back(travel.left_m.back() + s.left_m / 50);
      travel.right_m.push_back(travel.right_m.back() + s.right_m / 50);
    }
  const TrajectoryCovarianceSummary kelly = TrajectoryCovariance(travel, B);
  const PathCovarianceSummary seg = PredictPathCovariance(path, B, WheelNoise{1.0, 1.0}, PoseCovariance::Zero());
  CHECK(BasisError(kelly.motion, seg.motion) < 1e-11);
  const auto along = TrajectoryCovarianceAlong(travel, B);
  CHECK(BasisError(along.back(), kelly.motion) < 1e-11);
  // Initial-condition response is path independent (Kelly section 2.4).
  PoseCovariance P0 = PoseCovariance::Identity() * 0.01;
  const PoseCovariance p = kelly.Covariance(WheelNoise{}, P0);
  const Eigen::Matrix3d phi = PoseErrorTransition(Pose2{}, kelly.poses.back());
  CHECK(ScaledError(p, phi * P0 * phi.transpose()) < 1e-14);
}

TEST_CASE("path spec parsing", "[covariance]") {
  const auto p = ParsePathSpec("line:10, turn:-1.5707963 ,arc:1:2");
  REQUIRE(p.size() == 3);
  CHECK(p[0].kind == PathSegment::Kind::kLine);
  CHECK(p[1].a == Approx(-1.5707963));
  CHECK(p[2].b == 2.0);
  const auto w = ToWheelSegments(p, 0.4);
  CHECK(w[1].left_m == Approx(0.4 / 2 * 1.5707963));
  CHECK(PathSpecToString(p) == "line:10,turn:-1.5707963,arc:1:2");
  CHECK_THROWS_AS(ParsePathSpec(""), InvalidOptions);
  CHECK_THROWS_AS(ParsePathSpec("line:x"), InvalidOptions);
  CHECK_THROWS_AS(ParsePathSpec("line:1:2"), InvalidOptions);
  CHECK_THROWS_AS(ParsePathSpec("spiral:1"), InvalidOptions);
  CHECK_THROWS_AS(ParsePathSpec("line:1,,line:2"), InvalidOptions);
  CHECK_THROWS_AS(ParsePathSpec("line:nan"), InvalidOptions);
}
