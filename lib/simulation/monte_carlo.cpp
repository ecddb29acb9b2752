// Multithreaded Monte Carlo over runs with a thread-count-independent
// reduction; see monte_carlo.hpp.
#include "simulation/monte_carlo.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "simulation/monte_carlo_kernel.hpp"

namespace umbmark::sim {

std::string MonteCarloOptions::Check() const {
  if (runs < 2) return fmt::format("runs = {} must be >= 2", runs);
  if (threads < 0) return fmt::format("threads = {} must be >= 0 (0 = all cores)", threads);
  return {};
}

namespace {

/// Sums of one block, centred on a reference point to limit cancellation.
struct BlockSums {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
};

}  // namespace

MonteCarloSummary RunMonteCarlo(const SimPlan& plan, const MonteCarloOptions& options) {
  if (auto e = options.Check(); !e.empty()) throw InvalidOptions(e);
  const std::int64_t runs = options.runs;
  const std::int64_t block = 64;  // runs per work item (a multiple of kSimLanes)
  const std::int64_t nblocks = (runs + block - 1) / block;
  int threads = options.threads > 0 ? options.threads : static_cast<int>(std::thread::hardware_concurrency());
  threads = static_cast<int>(std::clamp<std::int64_t>(threads, 1, nblocks));

  // Reference: the noise-free true final pose (the plan with zero noise is
  // not needed; the first run is close enough and deterministic).
  Pose2 ref;
  SimulateFinalPoses(plan, options.seed, 0, 1, &ref);
  const Eigen::Vector3d r0(ref.x, ref.y, ref.theta);

  std::vector<BlockSums> sums(static_cast<std::size_t>(nblocks));
  MonteCarloSummary out;
  if (options.keep_runs) out.finals.resize(static_cast<std::size_t>(runs));
  std::atomic<std::int64_t> next{0};
  auto worker = [&]() {
    std::vector<Pose2> poses(static_cast<std::size_t>(block));
    for (std::int64_t k = next.fetch_add(1); k < nblocks; k = next.fetch_add(1)) {
      const std::int64_t first = k * block;
      const std::int64_t n = std::min(block, runs - first);
      SimulateFinalPoses(plan, options.seed, first, n, poses.data());
      BlockSums& s = sums[static_cast<std::size_t>(k)];
      for (std::int64_t i = 0; i < n; ++i) {
        const Pose2& p = poses[static_cast<std::size_t>(i)];
        const Eigen::Vector3d d = Eigen::Vector3d(p.x, p.y, p.theta) - r0;
        s.sum += d;
        s.outer += d * d.transpose();
        if (options.keep_runs) out.finals[static_cast<std::size_t>(first + i)] = p;
      }
    }
  };
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
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
