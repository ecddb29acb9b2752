#include "planning/check.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <tuple>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "effects/registry.hpp"
#include "error_models/path_covariance.hpp"
#include "error_models/wheel_noise_fit.hpp"
#include "error_models/wheel_noise_fit_data.hpp"

namespace umbmark::planning {

std::string CheckOptions::Check() const {
  if (noise) {
    if (auto e = noise->Check(); !e.empty()) return "noise: " + e;
  }
  if (ground_truth && !(ground_truth->sigma_xy_m >= 0.0 && ground_truth->sigma_theta_rad >= 0.0 &&
                        std::isfinite(ground_truth->sigma_xy_m) && std::isfinite(ground_truth->sigma_theta_rad)))
    return "ground_truth: sigma_xy_m and sigma_theta_rad must be finite numbers >= 0";
  if (!(max_correlation > 0.0 && max_correlation < 1.0))
    return fmt::format("max_correlation = {} must be in (0, 1)", max_correlation);
  if (!(rate_hz > 0.0 && rate_hz <= 10000.0)) return fmt::format("rate_hz = {} must be in (0, 10000]", rate_hz);
  for (const auto& [name, v] : {std::pair{"correction_E_d", correction_E_d}, std::pair{"correction_E_b", correction_E_b}})
    if (v && !(std::isfinite(*v) && *v > 0.0)) return fmt::format("{} = {} must be a finite factor > 0", name, *v);
  if (!(determined_fraction > 0.0 && determined_fraction <= 1.0))
    return fmt::format("determined_fraction = {} must be in (0, 1]", determined_fraction);
  if (max_extra_runs < 1 || max_extra_runs > 100000)
    return fmt::format("max_extra_runs = {} must be in [1, 100000]", max_extra_runs);
  return {};
}

namespace {

/// A driving time in the unit a person reads it in: s, min or h.
std::string DrivingTime(double seconds) {
  if (seconds >= 5400.0) return fmt::format("{:.1f} h", seconds / 3600.0);
  if (seconds >= 120.0) return fmt::format("{:.0f} min", seconds / 60.0);
  return fmt::format("{:.0f} s", seconds);
}

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Columns of the ground truth's footprint per run: the calibration
/// parameters and the diagnosis effects (see check.hpp).
enum Column { kEb, kEd, kEs, kDirectionAsymmetry, kCastorKick, kGtOffsetX, kGtOffsetY, kTimeOffset, kColumns };
/// The calibration parameters' names (columns kEb, kEd, kEs).
constexpr const char* kColumnName[3] = {"E_b", "E_d", "scale"};
/// Each column's mean-model term (effects::MeanTerm): the effect that takes
/// it names an effect column (ColumnName).
constexpr int kColumnTerm[kColumns] = {effects::kTermEb,   effects::kTermEd,    effects::kTermScale,
                                       effects::kTermAsym, effects::kTermKappa, effects::kTermDx,
                                       effects::kTermDy,   effects::kTermTau};
using Info = Eigen::Matrix<double, kColumns, kColumns>;

/// One run as the check sees it.
struct CheckRun {
  WheelTravel travel;
  std::vector<double> t_s;         ///< sample times (empty: 1/rate apart)
  std::vector<bool> ground_truth;  ///< per sample (empty: all)
  int direction = 0;               ///< square: -1 cw, +1 ccw; 0 otherwise
  bool square = false;
};

/// Odometry with backward wheel travel scaled by (1 + a).
std::vector<Pose2> WithAsymmetry(const WheelTravel& w, double b, double a) {
  WheelTravel m = w;
  for (std::size_t k = 1; k < w.left_m.size(); ++k) {
    const double dL = w.left_m[k] - w.left_m[k - 1], dR = w.right_m[k] - w.right_m[k - 1];
    m.left_m[k] = m.left_m[k - 1] + dL * (dL < 0.0 ? 1.0 + a : 1.0);
    m.right_m[k] = m.right_m[k - 1] + dR * (dR < 0.0 ? 1.0 + a : 1.0);
  }
  return IntegrateOdometry(m, b, Pose2{});
}

/// sum over ground-truth samples of C_k' C_k, C_k the 2 x kColumns footprint.
Info FootprintInformation(const CheckRun& r, double b, double rate_hz) {
  const std::size_t n = r.travel.left_m.size();
  Info M = Info::Zero();
  if (n < 2) return M;
  const Eigen::MatrixXd J = OdometryJacobian(r.travel, b);
  const std::vector<Pose2> p = IntegrateOdometry(r.travel, b, Pose2{});
  constexpr double h = 1e-6;
  const std::vector<Pose2> up = WithAsymmetry(r.travel, b, h), down = WithAsymmetry(r.travel, b, -h);
  auto time = [&](std::size_t k) { return r.t_s.empty() ? static_cast<double>(k) / rate_hz : r.t_s[k]; };
  // castor_kick: starts of a drive (|ds| beyond a spot turn's) after a standstill.
  std::vector<std::pair<std::size_t, double>> starts;
  bool still = true;
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const double dL = r.travel.left_m[k + 1] - r.travel.left_m[k], dR = r.travel.right_m[k + 1] - r.travel.right_m[k];
    if (dL == 0.0 && dR == 0.0) {
      still = true;
      continue;
    }
    const double ds = 0.5 * (dL + dR);
    if (still && std::abs(ds) > 0.25 * 0.5 * std::abs(dR - dL)) starts.emplace_back(k, ds > 0.0 ? 1.0 : -1.0);
    still = false;
  }
  for (std::size_t k = 1; k < n; ++k) {
    if (!r.ground_truth.empty() && !r.ground_truth[k]) continue;
    Eigen::Matrix<double, 2, kColumns> C = Eigen::Matrix<double, 2, kColumns>::Zero();
    C.leftCols<3>() = J.block<2, 3>(2 * static_cast<Eigen::Index>(k), 0);
    C(0, kDirectionAsymmetry) = (up[k].x - down[k].x) / (2.0 * h);
    C(1, kDirectionAsymmetry) = (up[k].y - down[k].y) / (2.0 * h);
    for (const auto& [s, sign] : starts) {
      if (s >= k) break;
      C(0, kCastorKick) += -sign * (p[k].y - p[s].y);
      C(1, kCastorKick) += sign * (p[k].x - p[s].x);
    }
    const double c = std::cos(p[k].theta), si = std::sin(p[k].theta);
    C(0, kGtOffsetX) = c - 1.0;
    C(1, kGtOffsetX) = si;
    C(0, kGtOffsetY) = -si;
    C(1, kGtOffsetY) = c - 1.0;
    const std::size_t a = k - 1, z = std::min(k + 1, n - 1);
    const double dt = time(z) - time(a);
    if (dt > 0.0) {
      C(0, kTimeOffset) = -(p[z].x - p[a].x) / dt;
      C(1, kTimeOffset) = -(p[z].y - p[a].y) / dt;
    }
    M += C.transpose() * C;
  }
  return M;
}

/// Cosine of the angle between column e and the span of `others`, from
/// the information M (uncentred multiple correlation); 1 when e has no
/// footprint.
double Collinearity(const Info& M, int e, const std::vector<int>& others) {
  if (!(M(e, e) > 0.0)) return 1.0;
  if (others.empty()) return 0.0;
  const auto k = static_cast<Eigen::Index>(others.size());
  Eigen::MatrixXd S(k, k);
  Eigen::VectorXd v(k);
  for (Eigen::Index i = 0; i < k; ++i) {
    v(i) = M(others[static_cast<std::size_t>(i)], e);
    for (Eigen::Index j = 0; j < k; ++j) S(i, j) = M(others[static_cast<std::size_t>(i)], others[static_cast<std::size_t>(j)]);
  }
  const double explained = v.dot(S.completeOrthogonalDecomposition().solve(v));
  return std::sqrt(std::clamp(explained / M(e, e), 0.0, 1.0));
}

/// Partial correlation of columns e and f given `given`.
double PartialCorrelation(const Info& M, int e, int f, const std::vector<int>& given) {
  std::vector<int> idx{e, f};
  idx.insert(idx.end(), given.begin(), given.end());
  const auto k = static_cast<Eigen::Index>(idx.size());
  Eigen::MatrixXd S(k, k);
  for (Eigen::Index i = 0; i < k; ++i)
    for (Eigen::Index j = 0; j < k; ++j) S(i, j) = M(idx[static_cast<std::size_t>(i)], idx[static_cast<std::size_t>(j)]);
  Eigen::Matrix2d schur = S.topLeftCorner<2, 2>();
  if (k > 2) {
    const Eigen::MatrixXd B = S.topRightCorner(2, k - 2), D = S.bottomRightCorner(k - 2, k - 2);
    schur -= B * D.completeOrthogonalDecomposition().solve(B.transpose());
  }
  if (!(schur(0, 0) > 1e-12 * M(e, e)) || !(schur(1, 1) > 1e-12 * M(f, f))) return 1.0;
  return std::abs(schur(0, 1)) / std::sqrt(schur(0, 0) * schur(1, 1));
}

/// A candidate addition: what it is, one run's contribution and time.
struct Addition {
  std::string text;  ///< "{n} ... " with {n} for the count
  double time_s = 0.0;
  Info footprint = Info::Zero();
  LeastSquaresTerms ls;
  std::vector<NoiseRunModel> noise;  ///< one of each run, count 1
};

/// Everything the checks read, so additions can be tried.
struct CampaignModel {
  Info footprint = Info::Zero();
  LeastSquaresTerms ls;
  std::vector<NoiseRunModel> noise_runs;
  Info footprint_along_path = Info::Zero();  ///< tape: the same runs seen along the path
  bool along_path = true;
};

/// The campaign's square side (first square experiment; 1 m without one).
double CampaignSide(const std::vector<CheckExperiment>& experiments) {
  for (const auto& e : experiments)
    if (e.kind == ExperimentKind::kSquare && e.side_m > 0.0) return e.side_m;
  return 1.0;
}

int DirectionOf(const TrajectoryRun& run, const std::vector<Pose2>& odometry) {
  if (run.direction == "cw") return -1;
  if (run.direction == "ccw") return 1;
  const double turn = odometry.empty() ? 0.0 : odometry.back().theta;
  return turn < -1.0 ? -1 : turn > 1.0 ? 1 : 0;
}

/// A synthetic run of `kind` as the campaign would record it.
CheckRun SyntheticRun(RunKind kind, double size, const std::vector<PathSegment>& spec, double b, bool along,
                      const CheckOptions& o) {
  CheckRun r;
  r.travel = SampleMotions(RunMotions(kind, size, spec, b, o.timing), b, o.rate_hz);
  if (!along) {
    r.ground_truth.assign(r.travel.left_m.size(), false);
    r.ground_truth.front() = r.ground_truth.back() = true;
  }
  r.square = kind == RunKind::kSquareCw || kind == RunKind::kSquareCcw;
  r.direction = kind == RunKind::kSquareCw ? -1 : kind == RunKind::kSquareCcw ? 1 : 0;
  return r;
}

std::vector<PathSegment> CirclePath(double radius, double b, bool ccw) {
  const double turn = 2.0 * kPi * (ccw ? 1.0 : -1.0);
  const double s = radius * 2.0 * kPi;
  return {PathSegment{PathSegment::Kind::kArc, s - 0.5 * b * turn, s + 0.5 * b * turn}};
}

/// The candidate additions (see check.hpp), each per unit.
std::vector<Addition> Candidates(double side, double b, bool along, const GroundTruthModel& gt,
                                 const WheelNoise& noise, const CheckOptions& o) {
  std::vector<Addition> out;
  auto add = [&](const std::string& text, const std::vector<std::pair<RunKind, std::vector<PathSegment>>>& runs,
                 double size, const std::string& group) {
    Addition a;
    a.text = text;
    int index = 0;
    for (const auto& [kind, spec] : runs) {
      const CheckRun r = SyntheticRun(kind, size, spec, b, along, o);
      a.time_s += MotionsDuration(RunMotions(kind, size, spec, b, o.timing));
      a.footprint += FootprintInformation(r, b, o.rate_hz);
      if (along && r.square) a.ls.Add(PathLeastSquaresTerms(r.travel, {}, b, noise, gt));
      const std::vector<PathSegment> path = kind == RunKind::kSquareCw    ? SquarePath(size, true)
                                            : kind == RunKind::kSquareCcw ? SquarePath(size, false)
                                            : kind == RunKind::kBackAndForth ? BackAndForthPath(size)
                                                                             : spec;
      const PathCovarianceSummary pc = PredictPathCovariance(ToWheelSegments(path, b), b, noise, PoseCovariance::Zero());
      a.noise.push_back({fmt::format("{}{}", group, index++), pc.motion,
                         MeasurementCovariance(gt.sigma_xy_m, gt.sigma_theta_rad, pc.mean), 1.0});
    }
    out.push_back(a);
  };
  add(fmt::format("{{}} cw square(s) of {:.2f} m", side), {{RunKind::kSquareCw, {}}}, side, "plan:cw");
  add(fmt::format("{{}} ccw square(s) of {:.2f} m", side), {{RunKind::kSquareCcw, {}}}, side, "plan:ccw");
  add(fmt::format("{{}} back-and-forth run(s) of {:.2f} m (driving backwards)", side), {{RunKind::kBackAndForth, {}}},
      side, "plan:fwd_back");
  const double radius = std::max(0.5, 0.5 * side);
  add(fmt::format("{{}} pair(s) of circles of radius {:.2f} m, one ccw and one cw", radius),
      {{RunKind::kFreePath, CirclePath(radius, b, true)}, {RunKind::kFreePath, CirclePath(radius, b, false)}}, 0.0,
      "plan:circles");
  return out;
}

/// Pairs of calibration parameters correlated beyond the threshold.
std::vector<std::pair<int, int>> ParameterPairs(const LeastSquaresTerms& ls, double max_correlation) {
  std::vector<std::pair<int, int>> out;
  const Eigen::Matrix3d c = ls.Covariance();
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j)
      if (c(i, i) > 0.0 && c(j, j) > 0.0 && std::abs(c(i, j)) / std::sqrt(c(i, i) * c(j, j)) > max_correlation)
        out.emplace_back(i, j);
  return out;
}

double NoiseCorrelation(const Eigen::Matrix2d& I) {
  if (!(I.determinant() > 1e-12 * I.diagonal().prod())) return 1.0;
  const Eigen::Matrix2d c = I.inverse();
  return std::abs(c(0, 1)) / std::sqrt(c(0, 0) * c(1, 1));
}

/// The cheapest addition (count x candidate) for which `separated` holds.
std::string SmallestAddition(const std::vector<Addition>& candidates, int min_count,
                             const std::function<bool(const Addition&, int)>& separated) {
  const Addition* best = nullptr;
  int best_n = 0;
  for (const Addition& a : candidates) {
    for (int n = min_count; n <= 20; ++n) {
      if (best && n * a.time_s >= best_n * best->time_s) break;
      if (separated(a, n)) {
        best = &a;
        best_n = n;
        break;
      }
    }
  }
  if (!best) return "no addition of up to 20 squares, back-and-forth runs or circles separates them";
  std::string text = best->text;
  text.replace(text.find("{}"), 2, std::to_string(best_n));
  return fmt::format("{} (about {} of driving)", text, DrivingTime(best_n * best->time_s));
}

}  // namespace

namespace {

/// The runs of the campaign and their fit-noise runs.
struct Gathered {
  std::vector<CheckRun> runs;
  std::vector<WheelNoiseFitRun> noise_runs;
  bool along_path = false;  ///< some square experiment has trajectories
  int cw = 0, ccw = 0, other = 0;
};

void GatherEndpoints(const CheckExperiment& e, const std::string& prefix, const RobotParams& robot,
                     const NoiseFitInputOptions& nin, const CheckOptions& o, Gathered* g) {
  const double b = robot.wheelbase_m;
  if (e.kind == ExperimentKind::kSquare) {
    for (const bool cw : {true, false}) {
      EndpointData part;
      part.path = e.endpoints->path;
      for (const ReturnError& r : e.endpoints->runs)
        if (r.direction == (cw ? "cw" : "ccw")) part.runs.push_back(r);
      if (part.runs.empty()) continue;
      (cw ? g->cw : g->ccw) += static_cast<int>(part.runs.size());
      for (std::size_t i = 0; i < part.runs.size(); ++i)
        g->runs.push_back(SyntheticRun(cw ? RunKind::kSquareCw : RunKind::kSquareCcw, e.side_m, {}, b, false, o));
      auto runs = NoiseRunsFromEndpoints(part, SquarePath(e.side_m, cw), b, prefix, nin);
      g->noise_runs.insert(g->noise_runs.end(), runs.begin(), runs.end());
    }
  } else if (e.kind == ExperimentKind::kBackAndForth) {
    g->other += static_cast<int>(e.endpoints->runs.size());
    for (std::size_t i = 0; i < e.endpoints->runs.size(); ++i)
      g->runs.push_back(SyntheticRun(RunKind::kBackAndForth, e.distance_m, {}, b, false, o));
    auto runs = NoiseRunsFromEndpoints(*e.endpoints, BackAndForthPath(e.distance_m), b, prefix, nin);
    g->noise_runs.insert(g->noise_runs.end(), runs.begin(), runs.end());
  }
}

Gathered Gather(const RobotParams& robot, const std::vector<CheckExperiment>& experiments,
                const GroundTruthModel& gt, const CheckOptions& o) {
  Gathered g;
  NoiseFitInputOptions nin;
  nin.sigma_xy_m = gt.sigma_xy_m;
  nin.sigma_theta_rad = gt.sigma_theta_rad;
  nin.second_order = false;
  for (std::size_t i = 0; i < experiments.size(); ++i) {
    const CheckExperiment& e = experiments[i];
    const std::string prefix = fmt::format("exp{}:", i + 1);
    if (e.endpoints) {
      GatherEndpoints(e, prefix, robot, nin, o, &g);
      continue;
    }
    if (!e.trajectories) continue;
    for (const TrajectoryRun& run : e.trajectories->runs) {
      if (run.size() < 2 || !run.HasGroundTruth(0)) continue;
      CheckRun r;
      r.travel = ComputeWheelTravel(run, robot, robot);
      r.t_s = run.t_s;
      r.ground_truth.resize(run.size());
      for (std::size_t k = 0; k < run.size(); ++k) r.ground_truth[k] = run.HasGroundTruth(k);
      r.square = e.kind == ExperimentKind::kSquare;
      if (r.square) {
        r.direction = DirectionOf(run, IntegrateOdometry(r.travel, robot.wheelbase_m, Pose2{}));
        if (r.direction == 0) continue;  // not a square the calibration can use
        (r.direction < 0 ? g.cw : g.ccw) += 1;
        g.along_path = true;
      } else {
        ++g.other;
      }
      g.runs.push_back(std::move(r));
    }
    auto runs = NoiseRunsFromTrajectories(*e.trajectories, robot, prefix, nin);
    g.noise_runs.insert(g.noise_runs.end(), runs.begin(), runs.end());
  }
  return g;
}

/// Wheel noise for the prediction: given (both uses), or fitted to the
/// campaign: r->noise from all of the return errors (what fit-noise
/// estimates, for k's half-widths), r->calibration_noise from their
/// positions alone (the plain fit and classic UMBmark see positions only;
/// a heading return error the positions do not share, such as a ground
/// truth's heading error after motion, is no wheel noise to them).
void NoiseFor(const Gathered& g, const CheckOptions& o, CheckResult* r) {
  if (o.noise) {
    r->noise = r->calibration_noise = *o.noise;
    return;
  }
  WheelNoiseFitOptions fo;
  fo.restricted = true;
  fo.intervals = false;
  try {
    const WheelNoiseFitSummary s = FitWheelNoise(g.noise_runs, fo);
    r->noise_fitted = true;
    r->noise = r->calibration_noise = {s.k_L, s.k_R};
  } catch (const std::exception& e) {
    throw QualityGateError(fmt::format("cannot fit the wheel noise from this campaign ({}); give --kl K --kr K", e.what()));
  }
  std::vector<WheelNoiseFitRun> positions = g.noise_runs;
  for (WheelNoiseFitRun& x : positions) x.has_theta = false;
  try {
    const WheelNoiseFitSummary p = FitWheelNoise(positions, fo);
    r->calibration_noise = {p.k_L, p.k_R};
  } catch (const std::exception&) {  // keep the full fit's (a note says which is used)
  }
  r->notes.push_back(fmt::format(
      "wheel noise fitted to this campaign (fit-noise, REML, first order): k_L = {:.3g}, k_R = {:.3g} m^1/2 from "
      "the return errors, for k's half-widths; k_L = {:.3g}, k_R = {:.3g} from their positions alone, for the "
      "calibration's (it sees positions only); give --kl/--kr to predict with other values",
      r->noise.k_L, r->noise.k_R, r->calibration_noise.k_L, r->calibration_noise.k_R));
}

/// A column's name: E_b, E_d, or the effect whose mean-model term it is.
std::string ColumnName(int c) {
  if (c == kEb || c == kEd) return kColumnName[c];
  const effects::Effect* e = effects::WithMeanTerm(kColumnTerm[c]);
  return e ? std::string(e->Name()) : std::string("?");
}

/// Effects (diagnosis) the footprint information cannot tell from the
/// baseline parameters or from each other (see check.hpp).
void EffectConfusions(const CampaignModel& cm, const std::vector<Addition>& adds, const CheckOptions& o,
                      std::vector<Confusion>* out) {
  const double mc = o.max_correlation;
  const std::vector<int> params{kEb, kEd};
  std::vector<int> effects{kEs, kDirectionAsymmetry, kCastorKick, kGtOffsetX, kGtOffsetY};
  if (cm.along_path) effects.push_back(kTimeOffset);
  auto excited = [](const Info& M, int e) { return M(e, e) > 1e-12 * std::max(1.0, M.trace()); };
  auto push = [&](Confusion c) {
    for (const Confusion& x : *out)
      if (x.what == c.what) return;
    out->push_back(std::move(c));
  };
  auto search = [&](const std::function<bool(const Info&)>& separated) {
    std::string add = SmallestAddition(adds, 1, [&](const Addition& a, int n) {
      return separated(cm.footprint + static_cast<double>(n) * a.footprint);
    });
    if (!cm.along_path && add.starts_with("no addition"))
      add = "ground truth along the path (motion capture or scans) on the same runs: closed paths seen at their end "
            "points only do not separate it (Kelly)";
    return add;
  };
  const Info& M = cm.footprint;
  for (int e : effects) {
    if (!excited(M, e)) {
      push({"effects", {ColumnName(e)}, search([&](const Info& N) { return excited(N, e) && Collinearity(N, e, params) <= mc; }),
            1.0});
      continue;
    }
    if (const double col = Collinearity(M, e, params); col > mc) {
      Confusion c{"effects", {ColumnName(e)}, "", col};
      for (int p : params)
        if (Collinearity(M, e, {p}) > 0.5) c.what.push_back(ColumnName(p));
      if (c.what.size() == 1) c.what.insert(c.what.end(), {"E_b", "E_d"});
      c.add = search([&](const Info& N) { return Collinearity(N, e, params) <= mc; });
      push(c);
    }
  }
  for (std::size_t i = 0; i < effects.size(); ++i) {
    for (std::size_t j = i + 1; j < effects.size(); ++j) {
      const int e = effects[i], f = effects[j];
      if ((e == kGtOffsetX && f == kGtOffsetY) || !excited(M, e) || !excited(M, f)) continue;
      if (const double pc = PartialCorrelation(M, e, f, params); pc > mc) {
        push({"effects", {ColumnName(e), ColumnName(f)},
              search([&](const Info& N) { return PartialCorrelation(N, e, f, params) <= mc; }), pc});
      }
    }
  }
}

std::vector<Confusion> Confusions(const CampaignModel& cm, const std::vector<Addition>& adds, const CheckResult& r,
                                  const CheckOptions& o) {
  std::vector<Confusion> out;
  const double mc = o.max_correlation;
  if (cm.along_path) {
    const Eigen::Matrix3d cov = cm.ls.Covariance();
    for (const auto& [i, j] : ParameterPairs(cm.ls, mc)) {
      Confusion c{"parameters", {kColumnName[i], kColumnName[j]}, "", std::abs(cov(i, j)) / std::sqrt(cov(i, i) * cov(j, j))};
      c.add = SmallestAddition(adds, 1, [&, i = i, j = j](const Addition& a, int n) {
        LeastSquaresTerms t = cm.ls;
        t.Add(a.ls, n);
        const auto pairs = ParameterPairs(t, mc);
        return std::find(pairs.begin(), pairs.end(), std::pair{i, j}) == pairs.end();
      });
      out.push_back(c);
    }
  }
  const double kc = NoiseCorrelation(NoiseInformation(cm.noise_runs, r.noise));
  if (kc > mc) {
    Confusion c{"noise", {"k_L", "k_R"}, "", kc};
    c.add = SmallestAddition(adds, 2, [&](const Addition& a, int n) {
      std::vector<NoiseRunModel> runs = cm.noise_runs;
      for (NoiseRunModel m : a.noise) {
        m.count = n;
        runs.push_back(m);
      }
      return NoiseCorrelation(NoiseInformation(runs, r.noise)) <= mc;
    });
    out.push_back(c);
  }
  EffectConfusions(cm, adds, o, &out);
  return out;
}

/// Predicted 95 % half-widths (E_d, E_b, scale) of the campaign's
/// calibration with m more square runs per direction; NaN where not
/// determined.
using WidthsWith = std::function<Eigen::Vector3d(int)>;

WidthsWith CalibrationWidths(const CampaignModel& cm, const Gathered& g, const std::vector<Addition>& adds,
                             double side, double b, const CheckResult& r) {
  if (g.along_path) {
    return [&cm, &adds](int m) {
      LeastSquaresTerms t = cm.ls;
      if (m > 0) t.Add(adds[0].ls, m).Add(adds[1].ls, m);
      const Eigen::Matrix3d c = t.Covariance();
      return Eigen::Vector3d(kZ95 * std::sqrt(c(1, 1)), kZ95 * std::sqrt(c(0, 0)), kZ95 * std::sqrt(c(2, 2)));
    };
  }
  auto ret = [&](bool cw) {
    const PathCovarianceSummary pc =
        PredictPathCovariance(ToWheelSegments(SquarePath(side, cw), b), b, r.calibration_noise, PoseCovariance::Zero());
    return Eigen::Matrix2d(
        (pc.covariance + MeasurementCovariance(r.ground_truth.sigma_xy_m, r.ground_truth.sigma_theta_rad, pc.mean))
            .topLeftCorner<2, 2>());
  };
  return [cw_cov = ret(true), ccw_cov = ret(false), n_cw = g.cw, n_ccw = g.ccw, side, b](int m) {
    if (n_cw + m < 1 || n_ccw + m < 1) return Eigen::Vector3d(kNaN, kNaN, kNaN);
    const Eigen::Matrix2d c = ClassicCovariance(cw_cov, n_cw + m, ccw_cov, n_ccw + m, side, b);
    return Eigen::Vector3d(kZ95 * std::sqrt(c(0, 0)), kZ95 * std::sqrt(c(1, 1)), kNaN);
  };
}

/// record_more (check.hpp): for each correction given whose half-width is
/// above determined_fraction |E - 1|, the fewest extra runs per direction
/// that bring it there (the half-width falls with m: bisection).
std::vector<RecordMore> RecordMoreRuns(const WidthsWith& widths, double pair_time_s, double side, const CheckOptions& o) {
  std::vector<RecordMore> out;
  for (const auto& [name, value, row] : {std::tuple{"E_d", o.correction_E_d, 0}, std::tuple{"E_b", o.correction_E_b, 1}}) {
    if (!value) continue;
    RecordMore m;
    m.quantity = name;
    m.correction = *value - 1.0;
    m.half_width = widths(0)(row);
    m.side_m = side;
    const double target = o.determined_fraction * std::abs(m.correction);
    if (!std::isfinite(m.half_width) || m.half_width <= target) continue;
    const auto meets = [&](int n) { return widths(n)(row) <= target; };
    int runs = o.max_extra_runs;
    if (meets(runs)) {
      int lo = 0;  // !meets(lo), meets(runs)
      while (runs - lo > 1) {
        const int mid = (lo + runs) / 2;
        (meets(mid) ? runs : lo) = mid;
      }
      m.extra_runs_per_direction = runs;
    }
    m.half_width_after = widths(runs)(row);
    m.time_s = runs * pair_time_s;
    out.push_back(m);
  }
  return out;
}

}  // namespace

CheckResult CheckCampaign(const RobotParams& robot, const std::vector<CheckExperiment>& experiments,
                          const CheckOptions& o) {
  if (auto e = o.Check(); !e.empty()) throw InvalidOptions(e);
  if (auto e = robot.Check(); !e.empty()) throw InvalidOptions("robot: " + e);
  CheckResult r;
  if (o.ground_truth) {
    r.ground_truth = *o.ground_truth;
  } else {
    r.notes.push_back("the manifest states no [ground_truth] noise: motion-capture values assumed (0.3 mm, 1 mrad)");
  }
  const double b = robot.wheelbase_m;
  Gathered g = Gather(robot, experiments, r.ground_truth, o);
  r.ground_truth.along_path = g.along_path;
  r.square_runs_cw = g.cw;
  r.square_runs_ccw = g.ccw;
  r.other_runs = g.other;
  if (g.cw + g.ccw == 0)
    throw InputError(experiments.empty() ? std::string() : experiments.front().label,
                     "no square run with ground truth at its start: the calibration cannot be predicted");
  NoiseFor(g, o, &r);
  r.method = g.along_path ? "plain_least_squares" : "umbmark_mean";
  const double side = CampaignSide(experiments);
  // Calibration.
  CampaignModel cm;
  cm.along_path = g.along_path;
  for (const CheckRun& run : g.runs) {
    cm.footprint += FootprintInformation(run, b, o.rate_hz);
    if (g.along_path && run.square)
      cm.ls.Add(PathLeastSquaresTerms(run.travel, run.ground_truth, b, r.calibration_noise, r.ground_truth));
  }
  const std::vector<Addition> adds = Candidates(side, b, g.along_path, r.ground_truth, r.calibration_noise, o);
  const WidthsWith widths = CalibrationWidths(cm, g, adds, side, b, r);
  const Eigen::Vector3d now = widths(0);
  if (std::isfinite(now(0))) r.predicted.E_d = now(0);
  if (std::isfinite(now(1))) r.predicted.E_b = now(1);
  if (std::isfinite(now(2))) r.predicted.scale = now(2);
  if (!g.along_path)
    r.notes.push_back("ground truth at the end points only: classic UMBmark holds the overall scale at the recorded value");
  r.record_more = RecordMoreRuns(widths, adds[0].time_s + adds[1].time_s, side, o);
  for (const auto& nr : g.noise_runs) cm.noise_runs.push_back({nr.group, nr.basis, nr.measurement, 1.0});
  const Eigen::Vector2d k = NoiseHalfWidths(NoiseInformation(cm.noise_runs, r.noise), r.noise);
  // A k the fit put at its boundary 0 has no interval the information can give.
  const double k_floor = 1e-3 * std::max(r.noise.k_L, r.noise.k_R);
  for (const auto& [value, width, name] : {std::tuple{r.noise.k_L, k(0), "k_L"}, std::tuple{r.noise.k_R, k(1), "k_R"}}) {
    if (!(value > k_floor)) {
      r.notes.push_back(fmt::format("{} = {:.2g} m^1/2 is at its boundary 0: this campaign does not determine it "
                                    "(its half-width is left out)",
                                    name, value));
      continue;
    }
    if (std::isfinite(width)) (std::string(name) == "k_L" ? r.predicted.k_L : r.predicted.k_R) = width;
  }
  r.cannot_separate = Confusions(cm, adds, r, o);
  return r;
}

std::string ConfusionMessage(const Confusion& c) {
  std::string what;
  for (std::size_t i = 0; i < c.what.size(); ++i)
    what += (i == 0 ? "" : i + 1 == c.what.size() ? " and " : ", ") + c.what[i];
  // "no addition ... separates them" is said as it is; anything else is what to add.
  const std::string add = c.add.starts_with("no addition") ? c.add : "add " + c.add;
  if (c.what.size() == 1) return fmt::format("{} is not excited or not determined by these runs: {}", what, add);
  return fmt::format("{} cannot be told apart on these runs (correlation {:.3f}): {}", what, c.correlation, add);
}

std::string RecordMoreMessage(const RecordMore& m) {
  const std::string head =
      m.half_width >= std::abs(m.correction)
          ? fmt::format("{}'s correction ({:+.3g} %) is not determined by these runs: its predicted 95 % half-width "
                        "is {:.3g} %",
                        m.quantity, 100.0 * m.correction, 100.0 * m.half_width)
          : fmt::format("{}'s correction ({:+.3g} %) is known only to +-{:.3g} % (predicted 95 % half-width)",
                        m.quantity, 100.0 * m.correction, 100.0 * m.half_width);
  if (m.extra_runs_per_direction == 0)
    return head + fmt::format("; even {} more of driving {:.2f} m squares would leave +-{:.3g} %: {}",
                              DrivingTime(m.time_s), m.side_m, 100.0 * m.half_width_after,
                              m.half_width_after >= std::abs(m.correction)
                                  ? "the correction is within the noise, keep the recorded value"
                                  : "it stays uncertain by more than half its size");
  return head + fmt::format("; record {} more square run(s) of {:.2f} m in each direction (about {} of driving) "
                            "to bring it to +-{:.3g} %, half the correction or less",
                            m.extra_runs_per_direction, m.side_m, DrivingTime(m.time_s), 100.0 * m.half_width_after);
}

}  // namespace umbmark::planning
