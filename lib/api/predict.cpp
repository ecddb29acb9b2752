// `umbmark predict` as a library call (see predict.hpp).
#include "api/predict.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "error_models/path_covariance.hpp"
#include "error_models/path_spec.hpp"
#include "error_models/second_order.hpp"
#include "simulation/monte_carlo.hpp"

namespace umbmark::api {

std::string PredictOptions::Check() const {
  if (std::string e = robot.Check(); !e.empty()) return e;
  for (const auto& [flag, k] : {std::pair{"--kl", k_L}, {"--kr", k_R}}) {
    if (!(std::isfinite(k) && k >= 0.0)) return fmt::format("{}: must be a finite number >= 0 (got '{}')", flag, k);
  }
  if (path.empty()) return "--path is required";
  if (monte_carlo && !(*monte_carlo >= 2 && *monte_carlo <= (std::int64_t{1} << 40)))
    return fmt::format("--monte-carlo: must be a number from 2 to 1.09951e+12 (got '{}')", *monte_carlo);
  if (!(partitions >= 1 && partitions <= (1 << 30)))
    return fmt::format("--partitions: must be a number from 1 to 1.07374e+09 (got '{}')", partitions);
  if (threads < 0) return fmt::format("--threads: must be a finite number >= 0 (got '{}')", threads);
  return {};
}

namespace {

/// P0: 3 values = diagonal variances [xx, yy, thth]; 6 = upper triangle
/// [xx, xy, xth, yy, yth, thth]; 9 = row-major 3x3.
PoseCovariance ParseP0(const std::vector<double>& v) {
  PoseCovariance P = PoseCovariance::Zero();
  if (v.empty()) return P;
  if (v.size() == 3) {
    P.diagonal() << v[0], v[1], v[2];
  } else if (v.size() == 6) {
    P << v[0], v[1], v[2], v[1], v[3], v[4], v[2], v[4], v[5];
  } else if (v.size() == 9) {
    P << v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8];
    if (!P.isApprox(P.transpose(), 1e-12)) throw InvalidOptions("--P0: the 3x3 matrix is not symmetric");
  } else {
    throw InvalidOptions(fmt::format("--P0 takes 3, 6 or 9 comma-separated values, got {}", v.size()));
  }
  if (!P.allFinite()) throw InvalidOptions("--P0: values must be finite");
  // A covariance has no negative variance along any direction.
  const Eigen::SelfAdjointEigenSolver<PoseCovariance> eig(P);
  const double lowest = eig.eigenvalues().minCoeff(), highest = eig.eigenvalues().cwiseAbs().maxCoeff();
  if (lowest < -1e-12 * std::max(1e-300, highest)) {
    throw InvalidOptions(fmt::format("--P0 is not positive semi-definite (smallest eigenvalue {:.3g}): a covariance "
                                     "needs |cov(a,b)| <= sqrt(var(a) var(b)) and no negative variance",
                                     lowest));
  }
  return P;
}

/// Longest wheel travel of one path segment [m]: 10,000 km, far beyond any
/// robot, far below where squared lengths overflow.
constexpr double kMaxWheelTravel_m = 1e7;

/// Memory and work of a Monte Carlo run, estimated before anything is
/// allocated: RunMonteCarlo keeps one 96-byte block of sums per 64 runs (so
/// the result does not depend on the thread count). Refused when it needs
/// more than half of this machine's memory.
void CheckMonteCarloSize(std::int64_t runs, int partitions, std::size_t segments) {
  const double bytes = std::ceil(static_cast<double>(runs) / 64.0) * 96.0;
  const double physical = static_cast<double>(::sysconf(_SC_PHYS_PAGES)) * static_cast<double>(::sysconf(_SC_PAGESIZE));
  const double budget = physical > 0 ? 0.5 * physical : 4e9;
  if (bytes > budget) {
    throw InvalidOptions(fmt::format("--monte-carlo {}: needs about {:.3g} GB of memory, more than half of this "
                                     "machine's {:.3g} GB; use at most {:.3g} runs",
                                     runs, bytes / 1e9, physical / 1e9, std::floor(budget / 96.0) * 64.0));
  }
  const double steps = static_cast<double>(runs) * partitions * static_cast<double>(std::max<std::size_t>(segments, 1));
  if (steps > 1e13) {
    throw InvalidOptions(fmt::format("--monte-carlo {} x --partitions {} x {} segments = {:.3g} wheel steps: days of "
                                     "computing at about 1e8 steps per second; lower the runs or partitions",
                                     runs, partitions, segments, steps));
  }
}

/// Path segments a wheel could not travel without overflowing the covariance.
void CheckWheelTravel(const std::vector<WheelSegment>& path) {
  for (std::size_t i = 0; i < path.size(); ++i) {
    const double longest = std::max(std::abs(path[i].left_m), std::abs(path[i].right_m));
    if (!(longest <= kMaxWheelTravel_m)) {
      throw InvalidOptions(fmt::format("--path segment {} makes a wheel travel {:.3g} m; the limit is {:.0e} m "
                                       "(longer paths overflow the covariance)",
                                       i + 1, longest, kMaxWheelTravel_m));
    }
  }
}

/// Fewer Monte Carlo runs than this: a warning (covariance SE above 14 %).
constexpr std::int64_t kFewMonteCarloRuns = 100;

/// The simulated final poses' mean and covariance with their standard
/// errors: the mean's sqrt(C_ii / n); the sample covariance's, for Gaussian
/// poses, sqrt((C_ii C_jj + C_ij^2) / (n - 1)) (Wishart variance).
PredictMonteCarlo MonteCarlo(const PredictOptions& o, const RobotParams& robot, const PoseCovariance& P0,
                             const std::vector<WheelSegment>& path, double theta_shift) {
  sim::SimulationModel model;
  model.nominal = robot;
  model.noise = {o.k_L, o.k_R};
  model.initial_covariance = P0;
  const sim::SimPlan plan = sim::CompilePlan(model, path, o.partitions);
  sim::MonteCarloOptions mo;
  mo.runs = *o.monte_carlo;
  mo.seed = o.seed;
  mo.threads = o.threads;
  mo.progress = o.progress;
  const sim::MonteCarloSummary mc = sim::RunMonteCarlo(plan, mo);
  PredictMonteCarlo out;
  out.mean = {mc.mean.x, mc.mean.y, mc.mean.theta + theta_shift};
  out.covariance = mc.covariance;
  const double runs = static_cast<double>(mc.runs);
  const PoseCovariance& C = mc.covariance;
  for (int i = 0; i < 3; ++i) {
    out.mean_se(i) = std::sqrt(std::max(C(i, i), 0.0) / runs);
    for (int k = 0; k < 3; ++k) out.covariance_se(i, k) = std::sqrt((C(i, i) * C(k, k) + C(i, k) * C(i, k)) / (runs - 1.0));
  }
  out.runs = mc.runs;
  out.partitions = o.partitions;
  out.seed = mc.seed;
  out.threads = mc.threads;
  out.steps = mc.runs * mc.steps_per_run;
  out.seconds = mc.seconds;
  out.steps_per_second = mc.steps_per_second;
  out.kernel = mc.kernel;
  return out;
}

/// Degenerate requests: a result, but one that says little (no motion, no
/// noise, too few Monte Carlo runs).
std::vector<std::string> DegenerateRequestWarnings(const PredictOptions& o, const std::vector<WheelSegment>& path,
                                                   const PoseCovariance& P0) {
  std::vector<std::string> warnings;
  const bool moves = std::any_of(path.begin(), path.end(), [](const WheelSegment& w) {
    return w.left_m != 0.0 || w.right_m != 0.0;
  });
  if (!moves) warnings.push_back("the path does not move (every segment has zero wheel travel): the prediction is P0");
  if (o.k_L == 0.0 && o.k_R == 0.0) {
    warnings.push_back(P0.isZero() ? "no noise at all (k_L = k_R = 0 and P0 = 0): the covariance is zero; take k_L, "
                                     "k_R from `umbmark fit-noise`"
                                   : "no wheel noise (k_L = k_R = 0): the covariance is P0 carried along the path; "
                                     "take k_L, k_R from `umbmark fit-noise`");
  }
  if (o.monte_carlo && *o.monte_carlo < kFewMonteCarloRuns) {
    warnings.push_back(fmt::format("Monte Carlo with {} runs: its covariance has a relative standard error of about "
                                   "sqrt(2/N) = {:.0f} % (see covariance_se); use {} runs or more",
                                   *o.monte_carlo, 100.0 * std::sqrt(2.0 / static_cast<double>(*o.monte_carlo)),
                                   kFewMonteCarloRuns));
  }
  return warnings;
}

nlohmann::json JsonMatrix(const PoseCovariance& P) {
  nlohmann::json rows = nlohmann::json::array();
  for (int i = 0; i < 3; ++i) rows.push_back({P(i, 0), P(i, 1), P(i, 2)});
  return rows;
}

}  // namespace

// Closed form, second order, optional Monte Carlo, gate, in order.
PredictResult Predict(const PredictOptions& o) {
  if (std::string err = o.Check(); !err.empty()) throw InvalidOptions(err);
  const RobotParams robot = o.robot.Resolve();
  const std::vector<PathSegment> spec = ParsePathSpec(o.path);
  const std::vector<WheelSegment> path = ToWheelSegments(spec, robot.wheelbase_m);
  CheckWheelTravel(path);
  PredictResult r;
  r.P0 = ParseP0(o.P0);
  if (o.monte_carlo) CheckMonteCarloSize(*o.monte_carlo, o.partitions, path.size());
  const WheelNoise noise{o.k_L, o.k_R};
  const PathCovarianceSummary pred = PredictPathCovariance(path, robot.wheelbase_m, noise, r.P0);
  // Mean heading wrapped to (-pi, pi]; the continuous value is reported too.
  const double theta_shift = WrapAngle(pred.mean.theta) - pred.mean.theta;
  r.path = PathSpecToString(spec);
  r.wheelbase_m = robot.wheelbase_m;
  r.k_L = o.k_L;
  r.k_R = o.k_R;
  for (const auto& w : path) r.segments.push_back({w.left_m, w.right_m, SegmentFormToString(SegmentFormOf(w))});
  r.mean = {pred.mean.x, pred.mean.y, pred.mean.theta + theta_shift};
  r.theta_continuous_rad = pred.mean.theta;
  r.covariance = pred.covariance;
  // Second-order (heading-squared) correction, docs/noise-model.md.
  const SecondOrderBasis q2 = SecondOrderHeadingBasis(path, robot.wheelbase_m);
  const Eigen::Vector3d dm = q2.Mean(noise, r.P0(2, 2));
  r.second_order = {{r.mean.x + dm(0), r.mean.y + dm(1), r.mean.theta},
                    pred.covariance + q2.Covariance(noise, r.P0(2, 2))};
  // Gate: never give a number that is not one.
  const bool finite = std::isfinite(r.mean.x) && std::isfinite(r.mean.y) && std::isfinite(r.mean.theta) &&
                      r.covariance.allFinite() && r.second_order.covariance.allFinite();
  if (!finite) {
    throw QualityGateError("the predicted mean or covariance is not finite (a path or noise constant too large for "
                           "double precision); shorten the path or check --kl/--kr");
  }
  if (o.monte_carlo) r.monte_carlo = MonteCarlo(o, robot, r.P0, path, theta_shift);
  r.warnings = DegenerateRequestWarnings(o, path, r.P0);
  return r;
}

nlohmann::json ToJson(const PredictResult& r) {
  nlohmann::json segments = nlohmann::json::array();
  for (const auto& s : r.segments) segments.push_back({{"left_m", s.left_m}, {"right_m", s.right_m}, {"form", s.form}});
  nlohmann::json j = {{"path", r.path},
                      {"wheelbase_m", r.wheelbase_m},
                      {"k_L", r.k_L},
                      {"k_R", r.k_R},
                      {"P0", JsonMatrix(r.P0)},
                      {"segments", segments},
                      {"mean", {r.mean.x, r.mean.y, r.mean.theta}},
                      {"theta_continuous_rad", r.theta_continuous_rad},
                      {"covariance", JsonMatrix(r.covariance)}};
  const Pose2& m2 = r.second_order.mean;
  j["second_order"] = {{"mean", {m2.x, m2.y, m2.theta}}, {"covariance", JsonMatrix(r.second_order.covariance)}};
  if (r.monte_carlo) {
    const PredictMonteCarlo& mc = *r.monte_carlo;
    j["monte_carlo"] = {{"mean", {mc.mean.x, mc.mean.y, mc.mean.theta}},
                        {"covariance", JsonMatrix(mc.covariance)},
                        {"mean_se", {mc.mean_se(0), mc.mean_se(1), mc.mean_se(2)}},
                        {"covariance_se", JsonMatrix(mc.covariance_se)},
                        {"runs", mc.runs},
                        {"partitions", mc.partitions},
                        {"seed", mc.seed},
                        {"threads", mc.threads},
                        {"steps", mc.steps},
                        {"seconds", mc.seconds},
                        {"steps_per_second", mc.steps_per_second},
                        {"kernel", mc.kernel}};
  }
  j["warnings"] = r.warnings;
  return j;
}

}  // namespace umbmark::api
