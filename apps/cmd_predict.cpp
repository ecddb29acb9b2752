// `umbmark predict --robot R.toml --kl K --kr K --path SPEC [--P0 ...]
//   [--monte-carlo RUNS [--partitions P] [--seed N] [--threads T]]`:
// closed-form mean pose and covariance after a path (Chong & Kleeman eqs.
// 23-28), optionally next to a Monte Carlo estimate of the same quantities
// (each segment split into P partitions with white wheel noise).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "common.hpp"
#include "progress.hpp"
#include "core/angles.hpp"
#include "core/errors.hpp"
#include "error_models/path_covariance.hpp"
#include "error_models/path_spec.hpp"
#include "error_models/second_order.hpp"
#include "simulation/monte_carlo.hpp"

namespace umbmark::cli {
namespace {

struct PredictOptions {
  RobotFlags robot;
  double k_L = 0.0, k_R = 0.0;
  std::string path;
  std::vector<double> p0;  // 3 (diagonal), 6 (upper triangle) or 9 (row-major) values
  std::optional<std::int64_t> mc_runs;
  int partitions = 1000;
  std::uint64_t seed = 1;
  int threads = 0;
  JsonFlag json;
};

/// --P0: 3 values = diagonal variances [xx, yy, thth]; 6 = upper triangle
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

nlohmann::json JsonMatrix(const PoseCovariance& P) {
  nlohmann::json rows = nlohmann::json::array();
  for (int i = 0; i < 3; ++i) rows.push_back({P(i, 0), P(i, 1), P(i, 2)});
  return rows;
}

void PrintCovariance(const char* title, const Pose2& mean, const PoseCovariance& P) {
  const double sx = std::sqrt(P(0, 0)), sy = std::sqrt(P(1, 1)), st = std::sqrt(P(2, 2));
  fmt::print("{}\n", title);
  fmt::print("  mean      x = {:.6g} m, y = {:.6g} m, theta = {:.6g} rad\n", mean.x, mean.y, mean.theta);
  fmt::print("  stddev    x = {:.6g} m, y = {:.6g} m, theta = {:.6g} rad\n", sx, sy, st);
  auto corr = [](double c, double a, double b) { return a > 0 && b > 0 ? 100.0 * c / (a * b) : 0.0; };
  fmt::print("  corr (%)  x-theta = {:.4f}, y-theta = {:.4f}, x-y = {:.4f}\n", corr(P(0, 2), sx, st),
             corr(P(1, 2), sy, st), corr(P(0, 1), sx, sy));
  fmt::print("  covariance [m, m, rad]:\n");
  for (int i = 0; i < 3; ++i) fmt::print("    {:>14.6e} {:>14.6e} {:>14.6e}\n", P(i, 0), P(i, 1), P(i, 2));
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

/// Standard errors of a Monte Carlo mean and covariance from n runs: the
/// mean's sqrt(C_ii / n); the sample covariance's, for Gaussian poses,
/// sqrt((C_ii C_jj + C_ij^2) / (n - 1)) (Wishart variance).
struct MonteCarloErrors {
  Eigen::Vector3d mean;
  PoseCovariance covariance;
};
MonteCarloErrors StandardErrors(const PoseCovariance& C, std::int64_t n) {
  MonteCarloErrors e;
  const double runs = static_cast<double>(n);
  for (int i = 0; i < 3; ++i) {
    e.mean(i) = std::sqrt(std::max(C(i, i), 0.0) / runs);
    for (int k = 0; k < 3; ++k) e.covariance(i, k) = std::sqrt((C(i, i) * C(k, k) + C(i, k) * C(i, k)) / (runs - 1.0));
  }
  return e;
}

/// Fewer Monte Carlo runs than this: a warning (covariance SE above 14 %).
constexpr std::int64_t kFewMonteCarloRuns = 100;

/// --path segments a wheel could not travel without overflowing the covariance.
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

/// --monte-carlo: the simulated final poses' mean and covariance with their
/// standard errors, printed unless `--json -`, as the JSON "monte_carlo".
nlohmann::json MonteCarlo(const PredictOptions& o, const RobotParams& robot, const WheelNoise& noise,
                          const PoseCovariance& P0, const std::vector<WheelSegment>& path, double theta_shift) {
  sim::SimulationModel model;
  model.nominal = robot;
  model.noise = noise;
  model.initial_covariance = P0;
  const sim::SimPlan plan = sim::CompilePlan(model, path, o.partitions);
  sim::MonteCarloOptions mo;
  mo.runs = *o.mc_runs;
  mo.seed = o.seed;
  mo.threads = o.threads;
  const sim::MonteCarloSummary mc = [&] {
    Progress progress(fmt::format("Monte Carlo, {} runs", mo.runs));
    mo.progress = progress.Callback();
    return sim::RunMonteCarlo(plan, mo);
  }();
  const Pose2 mc_mean{mc.mean.x, mc.mean.y, mc.mean.theta + theta_shift};
  const MonteCarloErrors se = StandardErrors(mc.covariance, mc.runs);
  nlohmann::json out = {{"mean", {mc_mean.x, mc_mean.y, mc_mean.theta}},
                        {"covariance", JsonMatrix(mc.covariance)},
                        {"mean_se", {se.mean(0), se.mean(1), se.mean(2)}},
                        {"covariance_se", JsonMatrix(se.covariance)},
                        {"runs", mc.runs},
                        {"partitions", o.partitions},
                        {"seed", mc.seed},
                        {"threads", mc.threads},
                        {"steps", mc.runs * mc.steps_per_run},
                        {"seconds", mc.seconds},
                        {"steps_per_second", mc.steps_per_second},
                        {"kernel", mc.kernel}};
  if (o.json.PrintText()) {
    fmt::print("\n");
    PrintCovariance(fmt::format("Monte Carlo ({} runs x {} partitions per segment, seed {}):", mc.runs,
                                o.partitions, mc.seed)
                        .c_str(),
                    mc_mean, mc.covariance);
    fmt::print("  standard error of the mean  x {:.3g} m, y {:.3g} m, theta {:.3g} rad\n", se.mean(0), se.mean(1),
               se.mean(2));
    fmt::print("  standard error of the covariance (Gaussian approximation) [m, m, rad]:\n");
    for (int i = 0; i < 3; ++i)
      fmt::print("    {:>14.6e} {:>14.6e} {:>14.6e}\n", se.covariance(i, 0), se.covariance(i, 1), se.covariance(i, 2));
    fmt::print("  {:.3e} wheel steps per second ({} threads, {} kernel, {:.3f} s)\n", mc.steps_per_second,
               mc.threads, mc.kernel, mc.seconds);
  }
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
  if (o.mc_runs && *o.mc_runs < kFewMonteCarloRuns) {
    warnings.push_back(fmt::format("Monte Carlo with {} runs: its covariance has a relative standard error of about "
                                   "sqrt(2/N) = {:.0f} % (see covariance_se); use {} runs or more",
                                   *o.mc_runs, 100.0 * std::sqrt(2.0 / static_cast<double>(*o.mc_runs)),
                                   kFewMonteCarloRuns));
  }
  return warnings;
}

// Closed form, optional Monte Carlo, gate and output, in order.
int RunPredict(const PredictOptions& o) {
  RegisterInputs({}, &o.robot);
  CommandOutputs().AddOutput("--json", o.json.path);
  CommandOutputs().Check();
  const RobotParams robot = o.robot.Resolve();
  const WheelNoise noise{o.k_L, o.k_R};
  const std::vector<PathSegment> spec = ParsePathSpec(o.path);
  const std::vector<WheelSegment> path = ToWheelSegments(spec, robot.wheelbase_m);
  CheckWheelTravel(path);
  const PoseCovariance P0 = ParseP0(o.p0);
  if (o.mc_runs) CheckMonteCarloSize(*o.mc_runs, o.partitions, path.size());
  const PathCovarianceSummary pred = PredictPathCovariance(path, robot.wheelbase_m, noise, P0);
  // Mean heading wrapped to (-pi, pi]; the continuous value is reported too.
  const double theta_shift = WrapAngle(pred.mean.theta) - pred.mean.theta;
  const Pose2 mean{pred.mean.x, pred.mean.y, pred.mean.theta + theta_shift};

  nlohmann::json segments = nlohmann::json::array();
  for (std::size_t i = 0; i < path.size(); ++i)
    segments.push_back({{"left_m", path[i].left_m},
                        {"right_m", path[i].right_m},
                        {"form", SegmentFormToString(SegmentFormOf(path[i]))}});
  nlohmann::json j = {{"path", PathSpecToString(spec)},
                      {"wheelbase_m", robot.wheelbase_m},
                      {"k_L", o.k_L},
                      {"k_R", o.k_R},
                      {"P0", JsonMatrix(P0)},
                      {"segments", segments},
                      {"mean", {mean.x, mean.y, mean.theta}},
                      {"theta_continuous_rad", pred.mean.theta},
                      {"covariance", JsonMatrix(pred.covariance)}};
  // Second-order (heading-squared) correction, docs/noise-model.md.
  const SecondOrderBasis q2 = SecondOrderHeadingBasis(path, robot.wheelbase_m);
  const Eigen::Vector3d dm = q2.Mean(noise, P0(2, 2));
  const Pose2 mean2{mean.x + dm(0), mean.y + dm(1), mean.theta};
  const PoseCovariance cov2 = pred.covariance + q2.Covariance(noise, P0(2, 2));
  j["second_order"] = {{"mean", {mean2.x, mean2.y, mean2.theta}}, {"covariance", JsonMatrix(cov2)}};
  if (o.json.PrintText()) {
    fmt::print("Path {} (wheelbase {} m, k_L = {} m^1/2, k_R = {} m^1/2)\n", PathSpecToString(spec),
               robot.wheelbase_m, o.k_L, o.k_R);
    PrintCovariance("Closed form (Chong & Kleeman eqs. 23-28):", mean, pred.covariance);
    fmt::print("\n");
    PrintCovariance("With the second-order heading term (track shortening):", mean2, cov2);
  }

  if (o.mc_runs) j["monte_carlo"] = MonteCarlo(o, robot, noise, P0, path, theta_shift);
  // Gate: never print or write a number that is not one.
  const bool finite = std::isfinite(mean.x) && std::isfinite(mean.y) && std::isfinite(mean.theta) &&
                      pred.covariance.allFinite() && cov2.allFinite();
  if (!finite) {
    throw QualityGateError("the predicted mean or covariance is not finite (a path or noise constant too large for "
                           "double precision); shorten the path or check --kl/--kr");
  }
  const std::vector<std::string> warnings = DegenerateRequestWarnings(o, path, P0);
  j["warnings"] = warnings;
  if (o.json.PrintText()) {
    for (const auto& w : warnings) fmt::print("  WARNING: {}\n", w);
  } else {
    for (const auto& w : warnings) fmt::print(stderr, "warning: {}\n", w);
  }
  o.json.Emit(j);
  return 0;
}

}  // namespace

Command SetupPredict(CLI::App& parent) {
  auto opts = std::make_shared<PredictOptions>();
  auto* app = parent.add_subcommand("predict", "Closed-form pose mean and covariance after a path (Chong & Kleeman)");
  opts->robot.Bind(*app);
  app->add_option("--kl", opts->k_L, "Left wheel noise constant k_L [m^1/2]")->required()->check(NonNegative());
  app->add_option("--kr", opts->k_R, "Right wheel noise constant k_R [m^1/2]")->required()->check(NonNegative());
  app->add_option("--path", opts->path, "Segments: line:D, turn:ANGLE_RAD, arc:L_LEFT:L_RIGHT (comma-separated)")
      ->required();
  app->add_option("--P0", opts->p0,
                  "Initial pose covariance: 3 values (variances xx,yy,thth), 6 (xx,xy,xth,yy,yth,thth) or 9 (row-major)")
      ->delimiter(',');
  app->add_option("--monte-carlo", opts->mc_runs, "Also estimate mean and covariance from RUNS simulated runs")
      ->check(NumberIn(2.0, 1099511627776.0));
  app->add_option("--partitions", opts->partitions, "Monte Carlo: partitions per segment")
      ->check(NumberIn(1.0, 1073741824.0))
      ->capture_default_str();
  app->add_option("--seed", opts->seed, "Monte Carlo: seed (run i uses streams derived from (seed, i))")
      ->check(SeedValidator())
      ->capture_default_str();
  app->add_option("--threads", opts->threads, "Monte Carlo: worker threads (0 = all cores)")
      ->check(NonNegative())
      ->capture_default_str();
  opts->json.Bind(*app);
  return {app, [opts] { return RunPredict(*opts); }};
}

}  // namespace umbmark::cli
