// Multithreaded Monte Carlo over runs with a thread-count-independent
// reduction; see monte_carlo.hpp.
#include "simulation/monte_carlo.hpp"

#include <algorithm>
#include <array>
#include <chrono>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "core/parallel_for.hpp"
#include "simulation/monte_carlo_kernel.hpp"

namespace umbmark::sim {

std::string MonteCarloOptions::Check() const {
  if (runs < 2) return fmt::format("runs = {} must be >= 2", runs);
  if (threads < 0) return fmt::format("threads = {} must be >= 0 (0 = all cores)", threads);
  return {};
}

namespace {

/// Runs per work item (a multiple of kSimLanes).
constexpr std::int64_t kBlock = 64;

/// Sums of one block, centred on a reference point to limit cancellation.
struct BlockSums {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
};

}  // namespace

MonteCarloSummary RunMonteCarlo(const SimPlan& plan, const MonteCarloOptions& options) {
  if (auto e = options.Check(); !e.empty()) throw InvalidOptions(e);
  const std::int64_t runs = options.runs;
  const std::int64_t nblocks = (runs + kBlock - 1) / kBlock;
  const int threads = static_cast<int>(std::clamp<std::int64_t>(ResolveThreads(options.threads), 1, nblocks));

  // Reference: the noise-free true final pose (the plan with zero noise is
  // not needed; the first run is close enough and deterministic).
  Pose2 ref;
  SimulateFinalPoses(plan, options.seed, 0, 1, &ref);
  const Eigen::Vector3d r0(ref.x, ref.y, ref.theta);

  std::vector<BlockSums> sums(static_cast<std::size_t>(nblocks));
  MonteCarloSummary out;
  if (options.keep_runs) out.finals.resize(static_cast<std::size_t>(runs));
  const auto t0 = std::chrono::steady_clock::now();
  ProgressCounter progress(options.progress, static_cast<double>(runs));
  ParallelFor(threads, nblocks, [&](std::int64_t k) {
    std::array<Pose2, kBlock> poses;
    const std::int64_t first = k * kBlock;
    const std::int64_t n = std::min(kBlock, runs - first);
    SimulateFinalPoses(plan, options.seed, first, n, poses.data());
    BlockSums& s = sums[static_cast<std::size_t>(k)];
    for (std::int64_t i = 0; i < n; ++i) {
      const Pose2& p = poses[static_cast<std::size_t>(i)];
      const Eigen::Vector3d d = Eigen::Vector3d(p.x, p.y, p.theta) - r0;
      s.sum += d;
      s.outer += d * d.transpose();
      if (options.keep_runs) out.finals[static_cast<std::size_t>(first + i)] = p;
    }
    progress.Add(static_cast<double>(n));
  });
  const auto t1 = std::chrono::steady_clock::now();

  BlockSums total;
  for (const BlockSums& s : sums) {  // block order: independent of threads
    total.sum += s.sum;
    total.outer += s.outer;
  }
  const double n = static_cast<double>(runs);
  const Eigen::Vector3d mean_d = total.sum / n;
  const Eigen::Matrix3d cov = (total.outer - n * mean_d * mean_d.transpose()) / (n - 1.0);
  out.mean = {r0.x() + mean_d.x(), r0.y() + mean_d.y(), r0.z() + mean_d.z()};
  out.covariance = 0.5 * (cov + cov.transpose());
  out.runs = runs;
  out.steps_per_run = plan.StepsPerRun();
  out.seed = options.seed;
  out.threads = threads;
  out.seconds = std::chrono::duration<double>(t1 - t0).count();
  out.steps_per_second = out.seconds > 0.0 ? n * static_cast<double>(out.steps_per_run) / out.seconds : 0.0;
  out.kernel = SimKernelName();
  return out;
}

}  // namespace umbmark::sim
