// Monte Carlo engine throughput on Chong & Kleeman's Table 1 set-up (arc with
// L = 3 m, R = 1 m, wheelbase 0.4 m, k_L = k_R = 0.001 m^1/2; 10^4 runs x
// 10^4 partitions), on one thread and on all cores, next to a plain scalar
// reference loop (std::mt19937_64 + std::normal_distribution, exact arc
// with sin/cos every step) in the same process. One step = one partition
// of one run. Reports wall-clock steps/s and steps per CPU-second (the
// latter is what a core delivers when other processes share the machine),
// and checks that engine and reference agree statistically.
//
// Usage: bench_simulator [--runs N] [--partitions P] [--reference-runs N] [--threads T] [--kernel NAME]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "simulation/monte_carlo.hpp"
#include "simulation/monte_carlo_kernel.hpp"

using namespace umbmark;

namespace {

constexpr double kNumpyStepsPerSecond = 3.4e7;  // vectorised NumPy, one core of the reference machine

double CpuSeconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

struct Stats {
  double mean[3] = {0, 0, 0};
  double var[3] = {0, 0, 0};
};

/// The plain loop: one run after another, std::normal_distribution for the
/// two wheels, sin/cos of the heading every step.
Stats ReferenceLoop(std::int64_t runs, int partitions, double L, double R, double B, double k, double* seconds,
                    double* cpu) {
  std::mt19937_64 rng(12345);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double ml = L / partitions, mr = R / partitions;
  const double sl = k * std::sqrt(std::abs(ml)), sr = k * std::sqrt(std::abs(mr));
  std::vector<double> xs, ys, ts;
  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = CpuSeconds();
  for (std::int64_t run = 0; run < runs; ++run) {
    double x = 0, y = 0, th = 0;
    for (int p = 0; p < partitions; ++p) {
      const double l = ml + sl * normal(rng), r = mr + sr * normal(rng);
      const double dth = (r - l) / B, ds = 0.5 * (l + r);
      const double half = 0.5 * dth;
      const double chord = std::abs(half) < 1e-9 ? ds : ds * std::sin(half) / half;
      x += chord * std::cos(th + half);
      y += chord * std::sin(th + half);
      th += dth;
    }
    xs.push_back(x);
    ys.push_back(y);
    ts.push_back(th);
  }
  *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  *cpu = CpuSeconds() - c0;
  Stats s;
  const std::vector<double>* v[3] = {&xs, &ys, &ts};
  for (int i = 0; i < 3; ++i) {
    for (double q : *v[i]) s.mean[i] += q;
    s.mean[i] /= static_cast<double>(runs);
    for (double q : *v[i]) s.var[i] += (q - s.mean[i]) * (q - s.mean[i]);
    s.var[i] /= static_cast<double>(runs - 1);
  }
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  std::int64_t runs = 10000, reference_runs = 1000;
  int partitions = 10000;
  int threads = 0;
  std::string kernel;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--kernel") {
      kernel = argv[i + 1];
      continue;
    }
    if (a == "--runs") runs = std::atoll(argv[i + 1]);
    else if (a == "--partitions") partitions = std::atoi(argv[i + 1]);
    else if (a == "--reference-runs") reference_runs = std::atoll(argv[i + 1]);
    else if (a == "--threads") threads = std::atoi(argv[i + 1]);
    else {
      std::fprintf(stderr, "unknown option %s\n", argv[i]);
      return 2;
    }
  }
  const double L = 3.0, R = 1.0, B = 0.4, k = 0.001;
  sim::SimulationModel m;
  m.nominal.wheelbase_m = B;
  m.nominal.wheel_diameter_left_m = m.nominal.wheel_diameter_right_m = 0.1;
  m.noise = {k, k};
  const sim::SimPlan plan = sim::CompilePlan(m, {{L, R}}, partitions);
  const int cores = static_cast<int>(std::thread::hardware_concurrency());
  if (!kernel.empty() && !sim::SelectSimKernel(kernel)) {
    std::fprintf(stderr, "kernel %s is not available on this CPU\n", kernel.c_str());
    return 2;
  }
  std::printf("Chong & Kleeman Table 1 set-up: L = %.0f m, R = %.0f m, b = %.1f m, k = %.3f m^1/2\n", L, R, B, k);
  std::printf("%lld runs x %d partitions = %.3g steps; kernel %s; %d hardware threads\n\n",
              static_cast<long long>(runs), partitions, static_cast<double>(runs) * partitions, sim::SimKernelName(),
              cores);
  std::printf("%-34s %8s %14s %16s %14s\n", "", "threads", "steps/s", "steps/CPU-s", "x NumPy/core");

  sim::MonteCarloSummary one;
  for (int t : {1, threads > 0 ? threads : cores}) {
    sim::MonteCarloOptions o;
    o.runs = runs;
    o.seed = 1;
    o.threads = t;
    const double c0 = CpuSeconds();
    const sim::MonteCarloSummary s = sim::RunMonteCarlo(plan, o);
    const double cpu = CpuSeconds() - c0;
    const double steps = static_cast<double>(runs) * partitions;
    const double per_cpu = steps / cpu;
    std::printf("%-34s %8d %14.3e %16.3e %14.1f\n", "engine (umbmark::sim)", s.threads, s.steps_per_second, per_cpu,
                per_cpu / kNumpyStepsPerSecond);
    if (t == 1) one = s;
  }
  double ref_wall = 0, ref_cpu = 0;
  const Stats ref = ReferenceLoop(reference_runs, partitions, L, R, B, k, &ref_wall, &ref_cpu);
  const double ref_steps = static_cast<double>(reference_runs) * partitions;
  std::printf("%-34s %8d %14.3e %16.3e %14.1f\n", "scalar reference (std::normal, sin/cos)", 1, ref_steps / ref_wall,
              ref_steps / ref_cpu, ref_steps / ref_cpu / kNumpyStepsPerSecond);
  std::printf("\nengine (1 thread) / scalar reference, wall clock: %.1fx\n",
              (static_cast<double>(runs) * partitions / one.seconds) / (ref_steps / ref_wall));

  // Same distribution: means within 4 standard errors, variances within 4
  // standard errors (normal theory).
  const double eng_mean[3] = {one.mean.x, one.mean.y, one.mean.theta};
  bool ok = true;
  std::printf("\n%-8s %14s %14s %14s %14s\n", "", "engine mean", "reference mean", "engine var", "reference var");
  for (int i = 0; i < 3; ++i) {
    const double v = one.covariance(i, i);
    const double n_eng = static_cast<double>(runs), n_ref = static_cast<double>(reference_runs);
    const double se_mean = std::sqrt(v / n_eng + ref.var[i] / n_ref);
    const double se_var = std::sqrt(2.0 * v * v / n_eng + 2.0 * ref.var[i] * ref.var[i] / n_ref);
    ok &= std::abs(eng_mean[i] - ref.mean[i]) < 4 * se_mean && std::abs(v - ref.var[i]) < 4 * se_var;
    std::printf("%-8s %14.6g %14.6g %14.6g %14.6g\n", i == 0 ? "x" : i == 1 ? "y" : "theta", eng_mean[i], ref.mean[i],
                v, ref.var[i]);
  }
  std::printf("engine and reference agree within 4 standard errors: %s\n", ok ? "yes" : "NO");
  return ok ? 0 : 1;
}
