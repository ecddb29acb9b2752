// Classic UMBmark calibration (see umbmark.hpp). Equation numbers refer to
// Borenstein & Feng, "Measurement and Correction of Systematic Odometry
// Errors in Mobile Robots".
#include "calibration/umbmark.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/angles.hpp"
#include "core/errors.hpp"

namespace umbmark {

const char* UmbmarkEstimatorToString(UmbmarkEstimator e) {
  switch (e) {
    case UmbmarkEstimator::kX: return "x";
    case UmbmarkEstimator::kY: return "y";
    case UmbmarkEstimator::kMean: return "mean";
  }
  return "?";
}

std::optional<UmbmarkEstimator> UmbmarkEstimatorFromString(std::string_view s) {
  if (s == "x") return UmbmarkEstimator::kX;
  if (s == "y") return UmbmarkEstimator::kY;
  if (s == "mean") return UmbmarkEstimator::kMean;
  return std::nullopt;
}

std::string UmbmarkOptions::Check() const {
  if (!std::isfinite(side_m) || !(side_m > 0.0)) return fmt::format("side_m = {} must be > 0 (square side in metres)", side_m);
  if (!std::isfinite(outlier_threshold) || !(outlier_threshold > 0.0))
    return fmt::format("outlier_threshold = {} must be > 0", outlier_threshold);
  return {};
}

UmbmarkEstimate EstimateFromCentres(double cw_cg, double ccw_cg, bool x_axis, double side_m,
                                    double recorded_wheelbase_m, bool ed_with_corrected_wheelbase) {
  const double L = side_m;
  UmbmarkEstimate e;
  if (x_axis) {
    e.beta_rad = (cw_cg - ccw_cg) / (-4.0 * L);   // eq. 4.20a (in radians)
    e.alpha_rad = (cw_cg + ccw_cg) / (-4.0 * L);  // eq. 4.24a
  } else {
    e.beta_rad = (cw_cg + ccw_cg) / (-4.0 * L);   // eq. 4.20b
    e.alpha_rad = (cw_cg - ccw_cg) / (-4.0 * L);  // eq. 4.24b
  }
  const double quarter = kPi / 2.0;
  e.E_b = quarter / (quarter - e.alpha_rad);  // eq. 4.27
  const double b = ed_with_corrected_wheelbase ? e.E_b * recorded_wheelbase_m : recorded_wheelbase_m;
  // eq. 4.21: R = (L/2) / sin(beta/2). eq. 4.22 is evaluated as
  // (1 + q)/(1 - q) with q = (b/2)/R = b sin(beta/2)/L, which is exact and
  // finite at beta = 0 (straight legs, R infinite, E_d = 1).
  const double s = std::sin(e.beta_rad / 2.0);
  e.R_m = s == 0.0 ? INFINITY : (L / 2.0) / s;
  const double q = b * s / L;
  e.E_d = (1.0 + q) / (1.0 - q);  // eq. 4.22, relative to the recorded D_R/D_L
  return e;
}

RobotParams ApplyCorrection(const RobotParams& recorded, double E_d, double E_b) {
  RobotParams p = recorded;
  p.wheelbase_m = E_b * recorded.wheelbase_m;                                  // eq. 4.26
  p.wheel_diameter_left_m = CorrectionLeft(E_d) * recorded.wheel_diameter_left_m;    // eqs. 4.29, 4.31
  p.wheel_diameter_right_m = CorrectionRight(E_d) * recorded.wheel_diameter_right_m;  // eqs. 4.30, 4.32
  return p;
}

namespace {

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Robust outlier score of each run: distance from its direction's
// coordinate-wise median, in units of a robust per-axis sigma. The sigma is
// pooled over both directions (the random error is the same mechanism in
// either) from the median distance: for isotropic Gaussian scatter the
// distance is Rayleigh distributed with median sigma*sqrt(2 ln 2). Needs at
// least 3 runs in a direction and 6 in all, else no score is given.
void ScoreRuns(std::vector<std::vector<RunFlag*>>& groups) {
  std::vector<double> all;
  std::vector<std::vector<double>> dist(groups.size());
  std::size_t total = 0;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    auto& runs = groups[g];
    if (runs.size() < 3) continue;
    std::vector<double> xs, ys;
    for (auto* r : runs) {
      xs.push_back(r->ex_m);
      ys.push_back(r->ey_m);
    }
    const double mx = Median(xs), my = Median(ys);
    for (auto* r : runs) dist[g].push_back(std::hypot(r->ex_m - mx, r->ey_m - my));
    all.insert(all.end(), dist[g].begin(), dist[g].end());
    total += runs.size();
  }
  if (total < 6) return;
  const double sigma = Median(all) / std::sqrt(2.0 * std::log(2.0));
  if (!(sigma > 0.0)) return;
  for (std::size_t g = 0; g < groups.size(); ++g)
    for (std::size_t i = 0; i < dist[g].size(); ++i) groups[g][i]->score = dist[g][i] / sigma;
}

ClusterStats Cluster(const std::vector<const RunFlag*>& runs) {
  std::vector<std::pair<double, double>> e;
  for (const auto* r : runs) e.emplace_back(r->ex_m, r->ey_m);
  return ClusterOf(e);
}

}  // namespace

ClusterStats ClusterOf(const std::vector<std::pair<double, double>>& errors_m) {
  ClusterStats c;
  c.n = static_cast<int>(errors_m.size());
  if (c.n == 0) return c;
  for (const auto& [ex, ey] : errors_m) {
    c.x_cg_m += ex;
    c.y_cg_m += ey;
  }
  c.x_cg_m /= c.n;  // eq. 3.2
  c.y_cg_m /= c.n;
  c.r_cg_m = std::hypot(c.x_cg_m, c.y_cg_m);  // eq. 3.3
  if (c.n > 1) {
    double ss = 0.0;
    for (const auto& [ex, ey] : errors_m) ss += std::pow(ex - c.x_cg_m, 2) + std::pow(ey - c.y_cg_m, 2);
    c.sigma_m = std::sqrt(ss / (c.n - 1));
    c.sem_m = c.sigma_m / std::sqrt(static_cast<double>(c.n));
  }
  return c;
}

UmbmarkSummary CalibrateUmbmark(const std::vector<ReturnError>& errors, const RobotParams& recorded,
                                const UmbmarkOptions& options, const std::string& source) {
  if (auto err = options.Check(); !err.empty()) throw InvalidOptions("UmbmarkOptions: " + err);
  if (auto err = recorded.Check(); !err.empty()) throw InvalidOptions("robot: " + err);

  UmbmarkSummary s;
  s.estimator = options.estimator;
  s.side_m = options.side_m;
  s.recorded = recorded;
  for (const auto& e : errors) {
    if (e.direction != "cw" && e.direction != "ccw") {
      throw InputError(source, e.line, 0,
                       fmt::format("run {}: direction '{}' is not cw or ccw (UMBmark needs square runs)", e.run,
                                   e.direction));
    }
    RunFlag f;
    f.run = e.run;
    f.direction = e.direction;
    f.ex_m = e.ex_m;
    f.ey_m = e.ey_m;
    f.excluded = std::find(options.exclude_runs.begin(), options.exclude_runs.end(), e.run) !=
                 options.exclude_runs.end();
    s.runs.push_back(std::move(f));
  }
  for (const auto& id : options.exclude_runs) {
    if (std::none_of(s.runs.begin(), s.runs.end(), [&](const RunFlag& f) { return f.run == id; }))
      throw InvalidOptions(fmt::format("exclude_runs: no run '{}' in {}", id, source.empty() ? "the input" : source));
  }

  std::vector<std::vector<RunFlag*>> groups(2);
  for (auto& f : s.runs)
    if (!f.excluded) groups[f.direction == "cw" ? 0 : 1].push_back(&f);
  ScoreRuns(groups);
  for (auto& f : s.runs) {
    f.outlier = f.score && *f.score > options.outlier_threshold;
    f.rejected = f.outlier && options.reject_outliers;
  }

  std::vector<const RunFlag*> cw, ccw;
  for (const auto& f : s.runs) {
    if (!f.used()) continue;
    (f.direction == "cw" ? cw : ccw).push_back(&f);
  }
  if (cw.empty() || ccw.empty()) {
    throw InputError(source, fmt::format("UMBmark needs runs in both directions; {} cw and {} ccw runs are usable",
                                         cw.size(), ccw.size()));
  }
  s.cw = Cluster(cw);
  s.ccw = Cluster(ccw);
  s.E_max_syst_m = std::max(s.cw.r_cg_m, s.ccw.r_cg_m);  // eq. 3.4

  const double b = recorded.wheelbase_m;
  const bool corr = options.ed_with_corrected_wheelbase;
  s.from_x = EstimateFromCentres(s.cw.x_cg_m, s.ccw.x_cg_m, true, options.side_m, b, corr);
  s.from_y = EstimateFromCentres(s.cw.y_cg_m, s.ccw.y_cg_m, false, options.side_m, b, corr);
  s.spread_E_d = std::abs(s.from_x.E_d - s.from_y.E_d);
  s.spread_E_b = std::abs(s.from_x.E_b - s.from_y.E_b);
  switch (options.estimator) {
    case UmbmarkEstimator::kX: s.selected = s.from_x; break;
    case UmbmarkEstimator::kY: s.selected = s.from_y; break;
    case UmbmarkEstimator::kMean: {
      // Footnote 2: E_d and E_b averaged over the x and y estimates.
      UmbmarkEstimate m;
      m.alpha_rad = 0.5 * (s.from_x.alpha_rad + s.from_y.alpha_rad);
      m.beta_rad = 0.5 * (s.from_x.beta_rad + s.from_y.beta_rad);
      const double sb = std::sin(m.beta_rad / 2.0);
      m.R_m = sb == 0.0 ? INFINITY : (options.side_m / 2.0) / sb;
      m.E_b = 0.5 * (s.from_x.E_b + s.from_y.E_b);
      m.E_d = 0.5 * (s.from_x.E_d + s.from_y.E_d);
      s.selected = m;
      break;
    }
  }
  s.c_L = CorrectionLeft(s.selected.E_d);
  s.c_R = CorrectionRight(s.selected.E_d);
  s.corrected = ApplyCorrection(recorded, s.selected.E_d, s.selected.E_b);
  s.sem_m = std::max(s.cw.sem_m, s.ccw.sem_m);
  s.compensation_worthwhile = s.E_max_syst_m > 3.0 * s.sem_m;
  return s;
}

}  // namespace umbmark
