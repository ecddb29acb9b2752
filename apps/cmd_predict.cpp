// `umbmark predict --robot R.toml --kl K --kr K --path SPEC [--P0 ...]
//   [--monte-carlo RUNS [--partitions P] [--seed N] [--threads T]]`:
// closed-form mean pose and covariance after a path (Chong & Kleeman eqs.
// 23-28), optionally next to a Monte Carlo estimate of the same quantities
// (each segment split into P partitions with white wheel noise). The
// command is the library's api::Predict (lib/api/predict.hpp): this file
// binds the flags to its options, and prints.
#include <cmath>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "api/predict.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "progress.hpp"

namespace umbmark::cli {
namespace {

/// The command line's options: the library's, and where the JSON goes.
struct PredictFlags {
  api::PredictOptions o;
  JsonFlag json;
};

void PrintCovariance(const std::string& title, const Pose2& mean, const PoseCovariance& P) {
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

void PrintMonteCarlo(const api::PredictMonteCarlo& mc) {
  fmt::print("\n");
  PrintCovariance(fmt::format("Monte Carlo ({} runs x {} partitions per segment, seed {}):", mc.runs, mc.partitions,
                              mc.seed),
                  mc.mean, mc.covariance);
  fmt::print("  standard error of the mean  x {:.3g} m, y {:.3g} m, theta {:.3g} rad\n", mc.mean_se(0), mc.mean_se(1),
             mc.mean_se(2));
  fmt::print("  standard error of the covariance (Gaussian approximation) [m, m, rad]:\n");
  for (int i = 0; i < 3; ++i)
    fmt::print("    {:>14.6e} {:>14.6e} {:>14.6e}\n", mc.covariance_se(i, 0), mc.covariance_se(i, 1),
               mc.covariance_se(i, 2));
  fmt::print("  {:.3e} wheel steps per second ({} threads, {} kernel, {:.3f} s)\n", mc.steps_per_second, mc.threads,
             mc.kernel, mc.seconds);
}

int RunPredict(PredictFlags& f) {
  CommandOutputs().AddInput(f.o.robot.robot_file);
  CommandOutputs().AddOutput("--json", f.json.path);
  CommandOutputs().Check();
  const api::PredictResult r = [&] {
    if (!f.o.monte_carlo) return api::Predict(f.o);
    Progress progress(fmt::format("Monte Carlo, {} runs", *f.o.monte_carlo));
    f.o.progress = progress.Callback();
    return api::Predict(f.o);
  }();
  if (f.json.PrintText()) {
    fmt::print("Path {} (wheelbase {} m, k_L = {} m^1/2, k_R = {} m^1/2)\n", r.path, r.wheelbase_m, r.k_L, r.k_R);
    PrintCovariance("Closed form (Chong & Kleeman eqs. 23-28):", r.mean, r.covariance);
    fmt::print("\n");
    PrintCovariance("With the second-order heading term (track shortening):", r.second_order.mean,
                    r.second_order.covariance);
    if (r.monte_carlo) PrintMonteCarlo(*r.monte_carlo);
    for (const auto& w : r.warnings) fmt::print("  WARNING: {}\n", w);
  } else {
    for (const auto& w : r.warnings) fmt::print(stderr, "warning: {}\n", w);
  }
  f.json.Emit(api::ToJson(r));
  return 0;
}

}  // namespace

Command SetupPredict(CLI::App& parent) {
  auto opts = std::make_shared<PredictFlags>();
  auto* app = parent.add_subcommand("predict", "Closed-form pose mean and covariance after a path (Chong & Kleeman)");
  BindRobot(*app, opts->o.robot);
  app->add_option("--kl", opts->o.k_L, "Left wheel noise constant k_L [m^1/2]")->required()->check(NonNegative());
  app->add_option("--kr", opts->o.k_R, "Right wheel noise constant k_R [m^1/2]")->required()->check(NonNegative());
  app->add_option("--path", opts->o.path, "Segments: line:D, turn:ANGLE_RAD, arc:L_LEFT:L_RIGHT (comma-separated)")
      ->required();
  app->add_option("--P0", opts->o.P0,
                  "Initial pose covariance: 3 values (variances xx,yy,thth), 6 (xx,xy,xth,yy,yth,thth) or 9 (row-major)")
      ->delimiter(',');
  app->add_option("--monte-carlo", opts->o.monte_carlo, "Also estimate mean and covariance from RUNS simulated runs")
      ->check(NumberIn(2.0, 1099511627776.0));
  app->add_option("--partitions", opts->o.partitions, "Monte Carlo: partitions per segment")
      ->check(NumberIn(1.0, 1073741824.0))
      ->capture_default_str();
  app->add_option("--seed", opts->o.seed, "Monte Carlo: seed (run i uses streams derived from (seed, i))")
      ->check(SeedValidator())
      ->capture_default_str();
  app->add_option("--threads", opts->o.threads, "Monte Carlo: worker threads (0 = all cores)")
      ->check(NonNegative())
      ->capture_default_str();
  opts->json.Bind(*app);
  return {app, [opts] { return RunPredict(*opts); }};
}

}  // namespace umbmark::cli
