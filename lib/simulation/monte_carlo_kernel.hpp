// The Monte Carlo engine's run simulator: executes a compiled SimPlan
// (monte_carlo_plan.hpp) for a range of runs and returns each run's true final
// pose, or its trace. Each run is a function of (plan, seed, run index) only.
//
// Kernel: runs are simulated kSimLanes at a time, one per SIMD lane, with
// branch-free arithmetic (fast_math.hpp) that the compiler vectorises; the
// best kernel for the CPU (AVX-512, AVX2+FMA, or baseline x86-64) is chosen
// at run time. Floating-point contraction is disabled in the kernels so all
// three give the same bits. Per partition and run:
//   1. two N(0,1) variates (Box-Muller, rng.hpp) from the run's stream,
//   2. l = mean_l + sigma_l z0, r = mean_r + sigma_r z1 (eq. 4 per partition),
//   3. exact arc: with h = (r - l)/(2b), chord = (l + r)/2 * sin(h)/h along
//      heading theta + h, heading theta + 2h. (cos, sin)(theta) is carried as
//      a unit complex number and rotated by (cos h, sin h) -- exact to
//      rounding, no approximation -- and re-synchronised with the
//      accumulated theta at every segment end. sin h, cos h and sin(h)/h are
//      polynomials valid for |h| <= pi/4; a segment whose partitions could
//      exceed that (largest Box-Muller variate included) runs a libm path.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/pose2.hpp"
#include "simulation/monte_carlo_plan.hpp"

namespace umbmark::sim {

/// Runs simulated together in one kernel call.
inline constexpr int kSimLanes = 16;

/// Name of the kernel in use ("avx512", "avx2", "baseline"); the best one
/// the CPU supports unless SelectSimKernel chose another.
const char* SimKernelName();

/// Kernels this CPU can run, best first.
std::vector<std::string> SimKernelsAvailable();

/// Uses kernel `name` from now on (tests and benchmarks compare kernels);
/// false when the CPU cannot run it. All kernels give identical results.
bool SelectSimKernel(const std::string& name);

/// True final pose (start frame, theta continuous) of runs first_run ..
/// first_run + count - 1, written to out[0 .. count-1].
void SimulateFinalPoses(const SimPlan& plan, std::uint64_t seed, std::int64_t first_run, std::int64_t count, Pose2* out);

/// One run recorded along the way.
struct RunTrace {
  std::int64_t run = 0;
  Pose2 start;                 ///< true start pose (sampled from P0)
  double phase_left = 0.0;     ///< encoder start phase [ticks] (quantised plans)
  double phase_right = 0.0;
  /// Samples after every `record_every` partitions and at every segment end:
  std::vector<int> segment;    ///< segment index of the sample
  std::vector<int> partition;  ///< partitions done in that segment (1..P)
  std::vector<Pose2> truth;    ///< true pose
  /// What the encoders report at each sample: cumulative wheel travel in
  /// nominal metres (whole ticks times metres per tick when quantised; the
  /// commanded travel, linear within a segment, otherwise).
  std::vector<double> wheel_left_m, wheel_right_m;
  /// Cumulative encoder counts (quantised plans only; empty otherwise).
  std::vector<std::int64_t> ticks_left, ticks_right;
};

/// Traces of runs first_run .. first_run + count - 1 (same numbers as
/// SimulateFinalPoses). record_every >= 1.
std::vector<RunTrace> SimulateTraces(const SimPlan& plan, std::uint64_t seed, std::int64_t first_run,
                                     std::int64_t count, int record_every);

}  // namespace umbmark::sim
