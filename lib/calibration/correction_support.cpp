// Statistical, model and label support of a UMBmark correction (see
// correction_support.hpp).
#include "calibration/correction_support.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "model/commanded_square.hpp"
#include "model/true_robot.hpp"
#include "stats/distributions.hpp"

namespace umbmark {
namespace {

/// Centre coordinates (x_cw, y_cw, x_ccw, y_ccw) [m].
using Centres = std::array<double, 4>;

/// (E_b, E_d) from the centres with the summary's estimator (the same
/// formulas as CalibrateUmbmark; eq. 4.22 with the corrected wheelbase).
std::array<double, 2> Estimate(const Centres& c, const UmbmarkSummary& s) {
  const double b = s.recorded.wheelbase_m;
  const UmbmarkEstimate x = EstimateFromCentres(c[0], c[2], true, s.side_m, b, true);
  const UmbmarkEstimate y = EstimateFromCentres(c[1], c[3], false, s.side_m, b, true);
  switch (s.estimator) {
    case UmbmarkEstimator::kX: return {x.E_b, x.E_d};
    case UmbmarkEstimator::kY: return {y.E_b, y.E_d};
    case UmbmarkEstimator::kMean: break;
  }
  return {0.5 * (x.E_b + y.E_b), 0.5 * (x.E_d + y.E_d)};
}

/// Sample covariance (xx, xy, yy) of the used runs of one direction about
/// their centre, divided by n: the covariance of the centre.
std::array<double, 3> CentreCovariance(const UmbmarkSummary& s, const char* dir, double cx, double cy, int n) {
  std::array<double, 3> c{0.0, 0.0, 0.0};
  for (const auto& r : s.runs) {
    if (!r.used() || r.direction != dir) continue;
    const double dx = r.ex_m - cx, dy = r.ey_m - cy;
    c[0] += dx * dx;
    c[1] += dx * dy;
    c[2] += dy * dy;
  }
  for (double& v : c) v /= static_cast<double>(n - 1) * n;
  return c;
}

}  // namespace

CorrectionSupport AnalyseCorrectionSupport(const UmbmarkSummary& s) {
  CorrectionSupport out;
  const Centres c0{s.cw.x_cg_m, s.cw.y_cg_m, s.ccw.x_cg_m, s.ccw.y_cg_m};
  const auto e0 = Estimate(c0, s);

  // Labels: distance of each centre from its own diagonal (cw: y = x,
  // ccw: y = -x) and from the other one.
  const double cw_on = (c0[0] + c0[1]) / std::sqrt(2.0), cw_off = (c0[0] - c0[1]) / std::sqrt(2.0);
  const double ccw_on = (c0[2] - c0[3]) / std::sqrt(2.0), ccw_off = (c0[2] + c0[3]) / std::sqrt(2.0);
  out.off_labels_m2 = cw_off * cw_off + ccw_off * ccw_off;
  out.off_reversed_m2 = cw_on * cw_on + ccw_on * ccw_on;

  // Model: round trip through the exact commanded square.
  {
    const double c_L = CorrectionLeft(e0[1]), c_R = CorrectionRight(e0[1]);
    const double b = s.recorded.wheelbase_m;
    if (std::isfinite(e0[0]) && std::isfinite(e0[1]) && e0[0] > 0.0 && c_L > 0.0 && c_R > 0.0) {
      const Pose2 cw = SquareReturnError(SquareDirection::kCw, s.side_m, b, e0[0], c_L, c_R);
      const Pose2 ccw = SquareReturnError(SquareDirection::kCcw, s.side_m, b, e0[0], c_L, c_R);
      const auto e1 = Estimate({cw.x, cw.y, ccw.x, ccw.y}, s);
      out.bias_E_b = e1[0] - e0[0];
      out.bias_E_d = e1[1] - e0[1];
    }
  }

  if (s.cw.n < 2 || s.ccw.n < 2) return out;
  out.scatter_known = true;
  out.t95 = StudentTQuantile(0.975, static_cast<double>(s.cw.n + s.ccw.n - 2));
  const auto cov_cw = CentreCovariance(s, "cw", c0[0], c0[1], s.cw.n);
  const auto cov_ccw = CentreCovariance(s, "ccw", c0[2], c0[3], s.ccw.n);

  // Delta method: gradient of (E_b, E_d) by central differences.
  const double h = 1e-6 * s.side_m;
  std::array<std::array<double, 4>, 2> g{};
  for (int k = 0; k < 4; ++k) {
    Centres up = c0, down = c0;
    up[k] += h;
    down[k] -= h;
    const auto eu = Estimate(up, s), ed = Estimate(down, s);
    for (int q = 0; q < 2; ++q) g[q][k] = (eu[q] - ed[q]) / (2.0 * h);
  }
  double var[2];
  for (int q = 0; q < 2; ++q) {
    const auto& d = g[q];
    var[q] = d[0] * d[0] * cov_cw[0] + 2.0 * d[0] * d[1] * cov_cw[1] + d[1] * d[1] * cov_cw[2] +
             d[2] * d[2] * cov_ccw[0] + 2.0 * d[2] * d[3] * cov_ccw[1] + d[3] * d[3] * cov_ccw[2];
  }
  out.se_E_b = std::sqrt(var[0]);
  out.se_E_d = std::sqrt(var[1]);

  // Off-diagonal components against their scatter; var(u) for
  // u = (x -+ y)/sqrt 2 is (xx + yy -+ 2 xy)/2.
  const double v_cw = 0.5 * (cov_cw[0] + cov_cw[2] - 2.0 * cov_cw[1]);
  const double v_ccw = 0.5 * (cov_ccw[0] + cov_ccw[2] + 2.0 * cov_ccw[1]);
  if (v_cw > 0.0 && v_ccw > 0.0) {
    const double p_cw = 2.0 * (1.0 - StudentTCdf(std::abs(cw_off) / std::sqrt(v_cw), s.cw.n - 1.0));
    const double p_ccw = 2.0 * (1.0 - StudentTCdf(std::abs(ccw_off) / std::sqrt(v_ccw), s.ccw.n - 1.0));
    const double fisher = -2.0 * (std::log(std::max(p_cw, 1e-300)) + std::log(std::max(p_ccw, 1e-300)));
    out.p_off_labels = ChiSquareSurvival(fisher, 4.0);
  }
  return out;
}

}  // namespace umbmark
