// Classic UMBmark on exact synthetic squares with known E_d and E_b: the
// estimate is exact to first order, so its error must be second order in the
// orientation errors alpha and beta (Borenstein & Feng linearise with
// sin(g) ~ g, cos(g) ~ 1). The squares are simulated here independently of
// the library: commanded (nominal) wheel travels, true diameters and
// wheelbase, exact constant-curvature arcs.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "calibration/umbmark.hpp"
#include "core/angles.hpp"

using namespace umbmark;

namespace {

struct P {
  double x = 0, y = 0, th = 0;
};

P Arc(P p, double dl, double dr, double b) {
  const double ds = 0.5 * (dl + dr), dth = (dr - dl) / b;
  if (std::abs(dth) < 1e-12) return {p.x + ds * std::cos(p.th), p.y + ds * std::sin(p.th), p.th};
  const double r = ds / dth;  // closed form of a constant-curvature arc
  return {p.x + r * (std::sin(p.th + dth) - std::sin(p.th)), p.y - r * (std::cos(p.th + dth) - std::cos(p.th)),
          p.th + dth};
}

// Return error of one square (4 legs of L, 4 spot turns of 90 deg) whose legs
// and turns stop when the nominal odometry reaches the target.
ReturnError Square(double E_d, double E_b, double L, const RobotParams& nominal, bool cw) {
  const double D = nominal.wheel_diameter_left_m, b = nominal.wheelbase_m;
  const double DL = D * 2.0 / (E_d + 1.0), DR = D * 2.0 * E_d / (E_d + 1.0), bt = E_b * b;
  const double s = cw ? -1.0 : 1.0;
  P p;
  for (int k = 0; k < 4; ++k) {
    p = Arc(p, L * DL / D, L * DR / D, bt);
    const double t = 0.5 * b * kPi / 2.0;
    p = Arc(p, -s * t * DL / D, s * t * DR / D, bt);
  }
  ReturnError e;
  e.direction = cw ? "cw" : "ccw";
  e.run = e.direction;
  e.ex_m = p.x;  // odometry returns to (0, 0, 0)
  e.ey_m = p.y;
  e.etheta_rad = WrapAngle(p.th);
  return e;
}

UmbmarkSummary Run(double E_d, double E_b, UmbmarkEstimator est, double L = 4.0) {
  RobotParams nominal{0.34, 0.15, 0.15, 2048.0};
  UmbmarkOptions o;
  o.side_m = L;
  o.estimator = est;
  return CalibrateUmbmark({Square(E_d, E_b, L, nominal, true), Square(E_d, E_b, L, nominal, false)}, nominal, o);
}

}  // namespace

TEST_CASE("UMBmark recovers small E_d, E_b within the small-angle error", "[umbmark][synthetic]") {
  // Bound (stated): |E_b error| <= 2 (alpha^2 + beta^2) and
  // |E_d error| <= 0.25 (alpha^2 + beta^2) for the x and y estimators, with
  // alpha, beta the estimated orientation errors in radians. Observed ratios
  // on these cases: up to 1.6 for E_b and 0.15 for E_d; the second-order
  // scaling itself is checked in the next test.
  for (auto [E_d, E_b] : {std::pair{1.004, 1.02}, {0.998, 0.99}, {1.001, 1.005}, {0.9995, 1.0}}) {
    for (auto est : {UmbmarkEstimator::kX, UmbmarkEstimator::kY}) {
      const auto s = Run(E_d, E_b, est);
      const double a = s.selected.alpha_rad, bt = s.selected.beta_rad;
      const double small = a * a + bt * bt;
      INFO("E_d " << E_d << " E_b " << E_b << " estimator " << UmbmarkEstimatorToString(est) << " alpha " << a
                  << " beta " << bt);
      CHECK(std::abs(s.selected.E_b - E_b) <= 2.0 * small + 1e-12);
      CHECK(std::abs(s.selected.E_d - E_d) <= 0.25 * small + 1e-12);
    }
    // The mean estimator lies between x and y, whose second-order errors
    // have opposite signs here, so it is at least as good as the worse one.
    const auto m = Run(E_d, E_b, UmbmarkEstimator::kMean);
    const auto x = Run(E_d, E_b, UmbmarkEstimator::kX), y = Run(E_d, E_b, UmbmarkEstimator::kY);
    CHECK(std::abs(m.selected.E_b - E_b) <= std::max(std::abs(x.selected.E_b - E_b), std::abs(y.selected.E_b - E_b)));
  }
}

TEST_CASE("UMBmark error is second order: halving the errors quarters it", "[umbmark][synthetic]") {
  double prev_b = 0, prev_d = 0;
  for (double scale : {1.0, 0.5, 0.25, 0.125}) {
    const double E_d = 1.0 + 0.004 * scale, E_b = 1.0 + 0.02 * scale;
    const auto s = Run(E_d, E_b, UmbmarkEstimator::kX);
    const double eb = std::abs(s.selected.E_b - E_b), ed = std::abs(s.selected.E_d - E_d);
    if (prev_b > 0) {
      CHECK(prev_b / eb == Approx(4.0).margin(0.5));
      CHECK(prev_d / ed == Approx(4.0).margin(0.5));
    }
    prev_b = eb;
    prev_d = ed;
  }
}

TEST_CASE("Paper's closed forms: centres of gravity of pure Type A and Type B errors", "[umbmark]") {
  // eqs. 4.17/4.18: x_cw = -2L(alpha + beta), x_ccw = -2L(alpha - beta); the
  // inverse (4.20a, 4.24a) must give back alpha and beta exactly.
  const double L = 4.0, alpha = 0.01, beta = -0.004;
  const auto e = EstimateFromCentres(-2 * L * (alpha + beta), -2 * L * (alpha - beta), true, L, 0.34, true);
  CHECK(e.alpha_rad == Approx(alpha).epsilon(1e-14));
  CHECK(e.beta_rad == Approx(beta).epsilon(1e-14));
  CHECK(e.E_b == Approx((kPi / 2) / (kPi / 2 - alpha)).epsilon(1e-14));  // eq. 4.27
  const double R = (L / 2) / std::sin(beta / 2);                             // eq. 4.21
  const double b = e.E_b * 0.34;
  CHECK(e.R_m == Approx(R).epsilon(1e-12));
  CHECK(e.E_d == Approx((R + b / 2) / (R - b / 2)).epsilon(1e-12));  // eq. 4.22
  // y-based: y_cw = -2L(alpha + beta), y_ccw = 2L(alpha - beta) (eqs. 4.8b, 4.12b, 4.16b)
  const auto ey = EstimateFromCentres(-2 * L * (alpha + beta), 2 * L * (alpha - beta), false, L, 0.34, true);
  CHECK(ey.alpha_rad == Approx(alpha).epsilon(1e-14));
  CHECK(ey.beta_rad == Approx(beta).epsilon(1e-14));
  // beta = 0: straight legs, E_d exactly 1 (R infinite).
  CHECK(EstimateFromCentres(0.01, 0.01, true, L, 0.34, true).E_d == 1.0);
}

TEST_CASE("Correction factors keep the mean diameter and compose", "[umbmark]") {
  for (double E_d : {0.99, 1.0, 1.0123}) {
    const double cL = CorrectionLeft(E_d), cR = CorrectionRight(E_d);
    CHECK(cR / cL == Approx(E_d).epsilon(1e-14));  // eqs. 4.31, 4.32
    CHECK(0.5 * (cL + cR) == Approx(1.0).epsilon(1e-14));
  }
  // A second pass on a compensated robot composes: correcting by E_d1 then
  // E_d2 gives the ratio E_d1 * E_d2 relative to the original.
  RobotParams r{0.3, 0.1, 0.1, std::nullopt};
  const auto p1 = ApplyCorrection(r, 1.01, 1.02);
  const auto p2 = ApplyCorrection(p1, 0.995, 0.99);
  CHECK(p2.wheel_diameter_right_m / p2.wheel_diameter_left_m == Approx(1.01 * 0.995).epsilon(1e-14));
  CHECK(p2.wheelbase_m == Approx(0.3 * 1.02 * 0.99).epsilon(1e-14));
}

TEST_CASE("Outliers are flagged, and rejected only when asked", "[umbmark]") {
  RobotParams nominal{0.34, 0.15, 0.15, std::nullopt};
  std::vector<ReturnError> errs;
  const double cw[][2] = {{-0.10, -0.05}, {-0.102, -0.049}, {-0.099, -0.052}, {-0.101, -0.048}, {-0.20, 0.10}};
  const double ccw[][2] = {{0.05, 0.10}, {0.051, 0.102}, {0.049, 0.099}, {0.052, 0.101}, {0.048, 0.098}};
  int id = 0;
  for (auto& c : cw) errs.push_back({std::to_string(++id), "cw", c[0], c[1], std::nullopt, 0, std::nullopt});
  for (auto& c : ccw) errs.push_back({std::to_string(++id), "ccw", c[0], c[1], std::nullopt, 0, std::nullopt});
  UmbmarkOptions o;
  o.side_m = 4.0;
  auto kept = CalibrateUmbmark(errs, nominal, o);
  REQUIRE(kept.runs[4].outlier);
  CHECK_FALSE(kept.runs[4].rejected);
  CHECK(kept.cw.n == 5);
  for (int i = 0; i < 10; ++i)
    if (i != 4) CHECK_FALSE(kept.runs[i].outlier);
  o.reject_outliers = true;
  auto rejected = CalibrateUmbmark(errs, nominal, o);
  CHECK(rejected.runs[4].rejected);
  CHECK(rejected.cw.n == 4);
  CHECK(rejected.cw.x_cg_m == Approx((-0.10 - 0.102 - 0.099 - 0.101) / 4));
  o.reject_outliers = false;
  o.exclude_runs = {"1", "6"};
  auto excl = CalibrateUmbmark(errs, nominal, o);
  CHECK(excl.cw.n == 4);
  CHECK(excl.ccw.n == 4);
  CHECK(excl.runs[0].excluded);
  o.exclude_runs = {"nope"};
  CHECK_THROWS_AS(CalibrateUmbmark(errs, nominal, o), InvalidOptions);
}

TEST_CASE("SEM and the 3*SEM rule", "[umbmark]") {
  // Paper, section 5: sigma about 25 mm over 5 runs gives SEM = 11.2 mm;
  // E_max,syst = 66 mm > 3*SEM = 33.6 mm -> a second pass is indicated.
  RobotParams nominal{0.34, 0.15, 0.15, std::nullopt};
  std::vector<ReturnError> errs;
  // Five cw runs on a circle of radius 25*sqrt(4/5) mm about (-66, 0) mm:
  // sum of squared distances = 5 * 20^2 * ... gives sigma = 25 mm exactly.
  const double r = 0.025 * std::sqrt(4.0 / 5.0);
  for (int i = 0; i < 5; ++i) {
    const double a = 2 * kPi * i / 5;
    errs.push_back({std::to_string(i), "cw", -0.066 + r * std::cos(a), r * std::sin(a), std::nullopt, 0, std::nullopt});
    errs.push_back({std::to_string(10 + i), "ccw", 0.01 + r * std::cos(a), r * std::sin(a), std::nullopt, 0, std::nullopt});
  }
  UmbmarkOptions o;
  o.side_m = 4.0;
  const auto s = CalibrateUmbmark(errs, nominal, o);
  CHECK(s.cw.sigma_m == Approx(0.025).epsilon(1e-12));
  CHECK(s.cw.sem_m == Approx(0.025 / std::sqrt(5.0)).epsilon(1e-12));
  CHECK(s.cw.sem_m * 1000 == Approx(11.18).margin(0.01));
  CHECK(s.E_max_syst_m == Approx(0.066).epsilon(1e-12));
  CHECK(s.compensation_worthwhile);
}
