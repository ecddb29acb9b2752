// Monte Carlo estimate of the final pose mean and covariance of a compiled
// plan (Chong & Kleeman section 6.1), multithreaded. Runs are grouped in
// fixed blocks of kSimLanes whose partial sums are reduced in block order,
// so the result is bitwise independent of the thread count.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "error_models/wheel_noise.hpp"
#include "core/pose2.hpp"
#include "core/progress.hpp"
#include "simulation/monte_carlo_plan.hpp"

namespace umbmark::sim {

struct MonteCarloOptions {
  /// Number of runs (>= 2).
  std::int64_t runs = 10000;
  /// Seed of every random stream; run i uses streams derived from (seed, i).
  std::uint64_t seed = 1;
  /// Worker threads; 0 = all hardware threads.
  int threads = 0;
  /// Keep every run's final pose in the summary (memory: 24 bytes per run).
  bool keep_runs = false;
  /// Progress in runs done of `runs` (core/progress.hpp). Default: none.
  ProgressCallback progress;

  /// Empty when valid, else a message naming the bad field.
  std::string Check() const;
};

struct MonteCarloSummary {
  /// Sample mean of the true final pose (theta continuous, not wrapped).
  Pose2 mean;
  /// Sample covariance (n - 1 denominator) of [x, y, theta].
  PoseCovariance covariance = PoseCovariance::Zero();
  std::int64_t runs = 0;
  std::int64_t steps_per_run = 0;  ///< partitions summed over segments
  std::uint64_t seed = 0;
  int threads = 0;                 ///< threads actually used
  double seconds = 0.0;            ///< wall-clock time of the simulation
  double steps_per_second = 0.0;   ///< runs * steps_per_run / seconds
  std::string kernel;              ///< SimKernelName()
  std::vector<Pose2> finals;       ///< per run, when keep_runs
};

/// Throws InvalidOptions for bad options.
MonteCarloSummary RunMonteCarlo(const SimPlan& plan, const MonteCarloOptions& options);

}  // namespace umbmark::sim
