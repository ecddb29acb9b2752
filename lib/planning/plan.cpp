#include "planning/plan.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "core/errors.hpp"
#include "error_models/path_covariance.hpp"
#include "error_models/wheel_noise_fit.hpp"

namespace umbmark::planning {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

const char* GroundTruthKindToString(GroundTruthKind k) {
  switch (k) {
    case GroundTruthKind::kMocap: return "mocap";
    case GroundTruthKind::kScan: return "scan";
    case GroundTruthKind::kTape: return "tape";
  }
  return "?";
}

std::optional<GroundTruthKind> GroundTruthKindFromString(std::string_view s) {
  if (s == "mocap") return GroundTruthKind::kMocap;
  if (s == "scan") return GroundTruthKind::kScan;
  if (s == "tape") return GroundTruthKind::kTape;
  return std::nullopt;
}

std::string PlanOptions::Check() const {
  if (auto e = robot.Check(); !e.empty()) return "robot: " + e;
  if (auto e = noise.Check(); !e.empty()) return "noise: " + e;
  auto positive = [](const char* name, const std::optional<double>& v) -> std::string {
    if (v && !(std::isfinite(*v) && *v > 0.0)) return fmt::format("{} = {} must be a finite number > 0", name, *v);
    return {};
  };
  for (const auto& [name, v] : {std::pair{"target_E_d", target_E_d}, std::pair{"target_E_b", target_E_b},
                                std::pair{"target_scale", target_scale}, std::pair{"target_k", target_k},
                                std::pair{"max_time_s", max_time_s}}) {
    if (auto e = positive(name, v); !e.empty()) return e;
  }
  for (const auto& [name, v] : {std::pair{"gt_sigma_xy_m", gt_sigma_xy_m}, std::pair{"gt_sigma_theta_rad", gt_sigma_theta_rad}}) {
    if (v && !(std::isfinite(*v) && *v >= 0.0)) return fmt::format("{} = {} must be a finite number >= 0", name, *v);
  }
  if (!target_E_d && !target_E_b && !target_scale && !target_k)
    return "no target: give at least one of target_E_d, target_E_b, target_scale, target_k";
  if (target_k && !(noise.k_L > 0.0 && noise.k_R > 0.0))
    return fmt::format("target_k needs wheel noise k_L, k_R > 0 to predict from (k_L = {}, k_R = {})", noise.k_L, noise.k_R);
  if (!(std::isfinite(min_side_m) && min_side_m > 0.0)) return fmt::format("min_side_m = {} must be > 0", min_side_m);
  if (!(std::isfinite(max_side_m) && max_side_m >= min_side_m))
    return fmt::format("max_side_m = {} must be a finite number >= min_side_m = {}", max_side_m, min_side_m);
  if (!(std::isfinite(timing.speed_m_s) && timing.speed_m_s > 0.0))
    return fmt::format("timing.speed_m_s = {} must be a finite number > 0", timing.speed_m_s);
  if (!(std::isfinite(timing.turn_rate_rad_s) && timing.turn_rate_rad_s > 0.0))
    return fmt::format("timing.turn_rate_rad_s = {} must be a finite number > 0", timing.turn_rate_rad_s);
  if (!(std::isfinite(timing.pause_s) && timing.pause_s >= 0.0))
    return fmt::format("timing.pause_s = {} must be a finite number >= 0", timing.pause_s);
  if (!(std::isfinite(rate_hz) && rate_hz > 0.0 && rate_hz <= 10000.0))
    return fmt::format("rate_hz = {} must be in (0, 10000]", rate_hz);
  if (min_runs_per_direction < 2) return fmt::format("min_runs_per_direction = {} must be >= 2", min_runs_per_direction);
  if (max_runs < min_runs_per_direction || max_runs > 100000)
    return fmt::format("max_runs = {} must be in [min_runs_per_direction, 100000]", max_runs);
  return {};
}

GroundTruthModel PlanOptions::GroundTruth() const {
  GroundTruthModel g;
  g.along_path = ground_truth != GroundTruthKind::kTape;
  const double xy = ground_truth == GroundTruthKind::kMocap ? 3e-4 : ground_truth == GroundTruthKind::kScan ? 5e-3 : 2e-3;
  const double th = ground_truth == GroundTruthKind::kMocap ? 1e-3 : 5e-3;
  g.sigma_xy_m = gt_sigma_xy_m.value_or(xy);
  g.sigma_theta_rad = gt_sigma_theta_rad.value_or(th);
  return g;
}

namespace {

/// One run kind at one size: its duration, calibration terms and noise model.
struct RunModel {
  double time_s = 0.0;
  LeastSquaresTerms ls;                                  ///< ground truth along the path
  Eigen::Matrix2d return_cov = Eigen::Matrix2d::Zero();  ///< (x, y) return error per run (classic)
  Eigen::Matrix2d noise_info = Eigen::Matrix2d::Zero();  ///< per run, ML
};

RunModel BuildRun(RunKind kind, double size, const std::vector<PathSegment>& spec, const PlanOptions& o) {
  const double b = o.robot.wheelbase_m;
  const GroundTruthModel gt = o.GroundTruth();
  RunModel m;
  const std::vector<Motion> motions = RunMotions(kind, size, spec, b, o.timing);
  m.time_s = MotionsDuration(motions);
  const std::vector<PathSegment> path = kind == RunKind::kSquareCw    ? SquarePath(size, true)
                                        : kind == RunKind::kSquareCcw ? SquarePath(size, false)
                                        : kind == RunKind::kBackAndForth ? BackAndForthPath(size)
                                                                         : spec;
  const PathCovarianceSummary pc =
      PredictPathCovariance(ToWheelSegments(path, b), b, o.noise, PoseCovariance::Zero());
  const PoseCovariance meas = MeasurementCovariance(gt.sigma_xy_m, gt.sigma_theta_rad, pc.mean);
  m.return_cov = (pc.covariance + meas).topLeftCorner<2, 2>();
  m.noise_info = RunNoiseInformation(pc.motion, meas, o.noise);
  if (gt.along_path && (kind == RunKind::kSquareCw || kind == RunKind::kSquareCcw)) {
    const WheelTravel travel = SampleMotions(motions, b, o.rate_hz);
    m.ls = PathLeastSquaresTerms(travel, {}, b, o.noise, gt);
  }
  return m;
}

/// Calibration half-widths (E_d, E_b, scale) of n cw and n ccw runs of one side.
struct CalibrationWidths {
  double E_d = kInf, E_b = kInf, scale = kInf;
};

CalibrationWidths SquareWidths(const RunModel& cw, const RunModel& ccw, int n_cw, int n_ccw, double side,
                               const PlanOptions& o) {
  CalibrationWidths w;
  if (n_cw < 1 || n_ccw < 1) return w;
  if (o.ground_truth == GroundTruthKind::kTape) {
    const Eigen::Matrix2d c = ClassicCovariance(cw.return_cov, n_cw, ccw.return_cov, n_ccw, side, o.robot.wheelbase_m);
    w.E_d = kZ95 * std::sqrt(c(0, 0));
    w.E_b = kZ95 * std::sqrt(c(1, 1));
    return w;  // the scale is held: never determined
  }
  LeastSquaresTerms t;
  t.Add(cw.ls, n_cw).Add(ccw.ls, n_ccw);
  // Column-normalised condition number: above 1e8 the fit is rank deficient (refine's gate).
  const Eigen::Vector3d d = t.A.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const Eigen::Matrix3d An = d.asDiagonal() * t.A * d.asDiagonal();
  const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(An).eigenvalues();
  if (!(ev(0) > 0.0) || ev(2) / ev(0) > 1e16) return w;  // condition number of J (sqrt) above 1e8
  const Eigen::Matrix3d c = t.Covariance();
  w.E_b = kZ95 * std::sqrt(c(0, 0));
  w.E_d = kZ95 * std::sqrt(c(1, 1));
  w.scale = kZ95 * std::sqrt(c(2, 2));
  return w;
}

Eigen::Vector2d KWidths(const RunModel& cw, const RunModel& ccw, int n, const RunModel* bf, int m,
                        const PlanOptions& o) {
  Eigen::Matrix2d I = (n - 1.0) * (cw.noise_info + ccw.noise_info);
  if (bf && m >= 2) I += (m - 1.0) * bf->noise_info;
  return NoiseHalfWidths(I, o.noise);
}

std::vector<double> SizeGrid(const PlanOptions& o) {
  std::vector<double> g;
  for (double s = o.min_side_m; s < o.max_side_m - 1e-9; s += 0.25) g.push_back(s);
  g.push_back(o.max_side_m);
  return g;
}

/// Runs per direction that bring a half-width of `one` (one run per
/// direction) down to `target` (covariance ~ 1/n).
int RunsFor(double one, double target) {
  if (!std::isfinite(one)) return std::numeric_limits<int>::max();
  const double n = std::ceil((one / target) * (one / target) - 1e-9);
  return n > 1e9 ? std::numeric_limits<int>::max() : std::max(1, static_cast<int>(n));
}

struct Candidate {
  PlanDesign design;
  std::string binding;
  bool found = false;
};

/// The cheapest back-and-forth addition (length, runs) that meets the k
/// target with n squares per direction; false when none does.
bool CheapestBackAndForth(const RunModel& cw, const RunModel& ccw, int n, const std::vector<double>& lengths,
                          const std::vector<RunModel>& bf, const PlanOptions& o, double* length, int* runs,
                          double* time) {
  bool any = false;
  for (std::size_t i = 0; i < lengths.size(); ++i) {
    auto meets = [&](int m) { return KWidths(cw, ccw, n, &bf[i], m, o).maxCoeff() <= *o.target_k; };
    if (!meets(o.max_runs)) continue;
    int lo = 1, hi = o.max_runs;  // meets(hi), !meets(lo) (m = 1 adds nothing: a group of one)
    while (hi - lo > 1) {
      const int mid = (lo + hi) / 2;
      (meets(mid) ? hi : lo) = mid;
    }
    const double t = hi * bf[i].time_s;
    if (!any || t < *time) {
      *length = lengths[i];
      *runs = hi;
      *time = t;
      any = true;
    }
  }
  return any;
}

/// The calibration targets' required runs per direction at one side, and
/// the largest (binding) of them.
int CalibrationRuns(const CalibrationWidths& one, const PlanOptions& o, std::string* binding) {
  int n = o.min_runs_per_direction;
  *binding = "min_runs_per_direction";
  for (const auto& [name, w, target] : {std::tuple{"E_d", one.E_d, o.target_E_d}, std::tuple{"E_b", one.E_b, o.target_E_b},
                                        std::tuple{"scale", one.scale, o.target_scale}}) {
    if (!target) continue;
    const int need = RunsFor(w, *target);
    if (need > n || (need == n && *binding == "min_runs_per_direction")) {
      n = need;
      *binding = name;
    }
  }
  return n;
}

}  // namespace

HalfWidths PredictDesign(const PlanDesign& d, const PlanOptions& o) {
  HalfWidths h;
  const RunModel cw = BuildRun(RunKind::kSquareCw, d.square_side_m, {}, o);
  const RunModel ccw = BuildRun(RunKind::kSquareCcw, d.square_side_m, {}, o);
  const CalibrationWidths w = SquareWidths(cw, ccw, d.runs_cw, d.runs_ccw, d.square_side_m, o);
  if (std::isfinite(w.E_d)) h.E_d = w.E_d;
  if (std::isfinite(w.E_b)) h.E_b = w.E_b;
  if (std::isfinite(w.scale)) h.scale = w.scale;
  Eigen::Matrix2d I = Eigen::Matrix2d::Zero();
  if (d.runs_cw >= 2) I += (d.runs_cw - 1.0) * cw.noise_info;
  if (d.runs_ccw >= 2) I += (d.runs_ccw - 1.0) * ccw.noise_info;
  if (d.back_and_forth_runs >= 2)
    I += (d.back_and_forth_runs - 1.0) * BuildRun(RunKind::kBackAndForth, d.back_and_forth_length_m, {}, o).noise_info;
  // Free paths: one group per path SPEC, one run each here (a group of one adds nothing).
  if (o.noise.k_L > 0.0 && o.noise.k_R > 0.0) {
    const Eigen::Vector2d k = NoiseHalfWidths(I, o.noise);
    if (std::isfinite(k(0))) h.k_L = k(0);
    if (std::isfinite(k(1))) h.k_R = k(1);
  }
  return h;
}

namespace {

/// Best design at one square side (see the search in plan.hpp).
Candidate BestAtSide(double side, const std::vector<double>& lengths, const std::vector<RunModel>& bf,
                     const PlanOptions& o, std::string* why_not) {
  Candidate best;
  const RunModel cw = BuildRun(RunKind::kSquareCw, side, {}, o), ccw = BuildRun(RunKind::kSquareCcw, side, {}, o);
  std::string binding;
  const int n0 = CalibrationRuns(SquareWidths(cw, ccw, 1, 1, side, o), o, &binding);
  if (n0 > o.max_runs) {
    const CalibrationWidths at_max = SquareWidths(cw, ccw, o.max_runs, o.max_runs, side, o);
    const double w = binding == "E_d" ? at_max.E_d : binding == "E_b" ? at_max.E_b : at_max.scale;
    *why_not = std::isfinite(w) ? fmt::format("{} runs per direction of a {:.2f} m square give the {} half-width {:.3g}; "
                                              "the target needs about {} runs",
                                              o.max_runs, side, binding, w, n0)
                                : fmt::format("a {:.2f} m square does not determine {}", side, binding);
    return best;
  }
  const double t_pair = cw.time_s + ccw.time_s;
  for (int n = n0; n <= o.max_runs; ++n) {
    const double t_sq = n * t_pair;
    if (best.found && t_sq >= best.design.time_s) break;
    PlanDesign d;
    d.square_side_m = side;
    d.runs_cw = d.runs_ccw = n;
    d.pause_s = o.timing.pause_s;
    d.time_s = t_sq;
    std::string bind = binding;
    if (o.target_k) {
      if (KWidths(cw, ccw, n, nullptr, 0, o).maxCoeff() > *o.target_k) {
        double len = 0.0, t_bf = 0.0;
        int m = 0;
        if (!CheapestBackAndForth(cw, ccw, n, lengths, bf, o, &len, &m, &t_bf)) continue;
        d.back_and_forth_runs = m;
        d.back_and_forth_length_m = len;
        d.time_s += t_bf;
      }
      if (n > n0 || d.back_and_forth_runs > 0) bind = "k";
    }
    if (!best.found || d.time_s < best.design.time_s) best = {d, bind, true};
    if (!o.target_k) break;
  }
  if (!best.found) *why_not = fmt::format("no number of runs up to {} meets the k target with a {:.2f} m square", o.max_runs, side);
  return best;
}

}  // namespace

PlanResult Plan(const PlanOptions& o) {
  if (auto e = o.Check(); !e.empty()) throw InvalidOptions(e);
  PlanResult r;
  const bool tape = o.ground_truth == GroundTruthKind::kTape;
  r.method = tape ? "umbmark_mean" : "plain_least_squares";
  if (tape && o.target_scale) {
    r.unmet = "scale: closed paths with ground truth at the end points only never determine the overall scale "
              "(Kelly): every leg scales together and the square still closes, and calibrate's classic UMBmark "
              "holds the scale at the recorded value. Measure it with ground truth along the path "
              "(--ground-truth mocap or scan), or drive a straight line of known length and measure it";
    return r;
  }
  if (o.ground_truth == GroundTruthKind::kScan)
    r.notes.push_back("scan ground truth: the overall scale rests on the lidar's range calibration");
  const std::vector<double> sizes = SizeGrid(o);
  std::vector<RunModel> bf;
  if (o.target_k)
    for (double len : sizes) bf.push_back(BuildRun(RunKind::kBackAndForth, len, {}, o));
  Candidate best;
  std::string why_not;
  for (double side : sizes) {
    std::string why;
    const Candidate c = BestAtSide(side, sizes, bf, o, &why);
    if (!c.found) {
      why_not = why;  // the largest side's reason is the last one
      continue;
    }
    if (!best.found || c.design.time_s < best.design.time_s - 1e-9) best = c;
  }
  if (!best.found) {
    r.unmet = why_not;
    return r;
  }
  r.design = best.design;
  r.binding = best.binding;
  r.predicted = PredictDesign(r.design, o);
  if (o.max_time_s && r.design.time_s > *o.max_time_s) {
    r.unmet = fmt::format("{}: the fastest design that meets it takes {:.0f} s of driving ({} + {} squares of {:.2f} m{}), "
                          "--max-time allows {:.0f} s",
                          r.binding, r.design.time_s, r.design.runs_cw, r.design.runs_ccw, r.design.square_side_m,
                          r.design.back_and_forth_runs > 0
                              ? fmt::format(", {} back-and-forth runs of {:.2f} m", r.design.back_and_forth_runs,
                                            r.design.back_and_forth_length_m)
                              : "",
                          *o.max_time_s);
  }
  if (r.design.back_and_forth_runs > 0 && !tape)
    r.notes.push_back("calibrate on the square runs alone (a manifest without the back-and-forth experiment) and run "
                      "fit-noise on all: back-and-forth runs are closed paths that barely tell calibrations apart, so "
                      "as calibrate's held-out paths they would make its recommendation a toss-up between ties");
  if (r.design.runs_cw < 4)
    r.notes.push_back("fewer than 4 runs per direction: calibrate warns, and its intervals are optimistic below 4-5");
  r.notes.push_back("times assume no acceleration phase and do not count driving back to the start between runs");
  return r;
}

std::vector<DesignMotion> DesignMotions(const PlanDesign& d, const PlanOptions& o) {
  std::vector<DesignMotion> out;
  int run = 0;
  auto add = [&](RunKind kind, double size, const std::vector<PathSegment>& spec) {
    ++run;
    for (const Motion& m : RunMotions(kind, size, spec, o.robot.wheelbase_m, o.timing)) out.push_back({run, kind, m});
  };
  for (int i = 0; i < std::max(d.runs_cw, d.runs_ccw); ++i) {
    if (i < d.runs_cw) add(RunKind::kSquareCw, d.square_side_m, {});
    if (i < d.runs_ccw) add(RunKind::kSquareCcw, d.square_side_m, {});
  }
  for (int i = 0; i < d.back_and_forth_runs; ++i) add(RunKind::kBackAndForth, d.back_and_forth_length_m, {});
  for (const std::string& spec : d.free_paths) add(RunKind::kFreePath, 0.0, ParsePathSpec(spec));
  return out;
}

}  // namespace umbmark::planning
