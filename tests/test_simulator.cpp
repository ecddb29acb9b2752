// Monte Carlo engine: the branch-free math against libm, the normal
// generator's distribution, exactness of the arc integration, the true-vs-
// nominal robot model, encoder quantisation, and reproducibility from
// (seed, run index) independent of lanes and threads.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/angles.hpp"
#include "error_models/path_covariance.hpp"
#include "kinematics/diff_drive.hpp"
#include "model/commanded_square.hpp"
#include "simulation/fast_math.hpp"
#include "simulation/monte_carlo.hpp"
#include "simulation/rng.hpp"
#include "simulation/monte_carlo_kernel.hpp"

using namespace umbmark;
using namespace umbmark::sim;

namespace {

double Ulp(double x) { return std::nextafter(std::abs(x), INFINITY) - std::abs(x); }

SimulationModel BasicModel(double wheelbase, double k_L, double k_R) {
  SimulationModel m;
  m.nominal.wheelbase_m = wheelbase;
  m.nominal.wheel_diameter_left_m = 0.1;
  m.nominal.wheel_diameter_right_m = 0.1;
  m.noise = {k_L, k_R};
  return m;
}

/// Straightforward scalar re-implementation of one run (same streams, libm
/// trigonometry, DiffDriveStep per partition), for a plan without P0 and
/// without quantisation.
Pose2 ScalarReferenceRun(const SimPlan& plan, std::uint64_t seed, std::uint64_t run) {
  Xoshiro256pp g(StreamSeed(seed, run, kStreamWheelNoise));
  Pose2 p{};
  for (const SimSegment& s : plan.segments) {
    const double ml = s.left_m / s.partitions, mr = s.right_m / s.partitions;
    const double sl = plan.noise.k_L * std::sqrt(std::abs(ml)), sr = plan.noise.k_R * std::sqrt(std::abs(mr));
    for (int i = 0; i < s.partitions; ++i) {
      const std::uint64_t a = g.Next(), b = g.Next();
      double z0, z1;
      NormalPairFromBits(a, b, z0, z1);
      p = DiffDriveStep(p, ml + sl * z0, mr + sr * z1, plan.true_wheelbase_m, Integrator::kArc);
    }
  }
  return p;
}

}  // namespace

TEST_CASE("branch-free math agrees with libm on its domains", "[simulator]") {
  Xoshiro256pp g(42);
  double worst_log = 0, worst_sqrt = 0, worst_sin = 0, worst_cos = 0, worst_sinc = 0, worst_tiny = 0;
  for (int i = 0; i < 200000; ++i) {
    // ln on (0, 1]: uniform and log-uniform arguments.
    const double u = i % 2 ? 2.0 - fm::One52(g.Next()) : std::exp2(-52.0 * fm::Unit52(g.Next()));
    worst_log = std::max(worst_log, std::abs(fm::LogUnit(u) - std::log(u)) / std::max(Ulp(std::log(u)), 1e-300));
    const double x = 80.0 * fm::Unit52(g.Next()) * (i % 3 ? 1.0 : 1e-12);
    worst_sqrt = std::max(worst_sqrt, std::abs(fm::Sqrt(x) - std::sqrt(x)) / Ulp(std::sqrt(x) + 1e-300));
    const double a = (fm::kPi / 4) * (2.0 * fm::Unit52(g.Next()) - 1.0);
    double s, c;
    fm::SinCosQuarter(a, s, c);
    worst_sin = std::max(worst_sin, std::abs(s - std::sin(a)) / Ulp(std::sin(a)));
    worst_cos = std::max(worst_cos, std::abs(c - std::cos(a)) / Ulp(std::cos(a)));
    double sinc, c2;
    fm::SincCosQuarter(a, sinc, c2);
    worst_sinc = std::max(worst_sinc, std::abs(sinc * a - std::sin(a)) / Ulp(std::sin(a)));
    const double t = a / 12.6;  // |t| <= 1/16
    fm::SincCosTiny(t, sinc, c2);
    worst_tiny = std::max(worst_tiny, std::max(std::abs(sinc * t - std::sin(t)) / Ulp(std::sin(t)),
                                               std::abs(c2 - std::cos(t)) / Ulp(std::cos(t))));
  }
  CHECK(fm::LogUnit(1.0) == 0.0);
  CHECK(fm::LogUnit(std::exp2(-52)) == Approx(-52 * std::log(2.0)).epsilon(1e-16));
  CHECK(fm::Sqrt(0.0) == 0.0);
  CHECK(worst_log <= 2.0);
  CHECK(worst_sqrt <= 1.0);
  CHECK(worst_sin <= 2.0);
  CHECK(worst_cos <= 2.0);
  CHECK(worst_sinc <= 3.0);
  CHECK(worst_tiny <= 2.0);
}

TEST_CASE("Box-Muller pairs are independent standard normals", "[simulator]") {
  Xoshiro256pp g(7);
  const int n = 400000;  // pairs
  std::vector<double> z;
  z.reserve(2 * n);
  double s01 = 0.0;
  for (int i = 0; i < n; ++i) {
    double a, b;
    NormalPairFromBits(g.Next(), g.Next(), a, b);
    z.push_back(a);
    z.push_back(b);
    s01 += a * b;
    REQUIRE(std::abs(a) <= kMaxAbsNormal);
  }
  const double N = static_cast<double>(z.size());
  double m1 = 0, m2 = 0, m3 = 0, m4 = 0;
  for (double v : z) {
    m1 += v;
    m2 += v * v;
    m3 += v * v * v;
    m4 += v * v * v * v;
  }
  m1 /= N, m2 /= N, m3 /= N, m4 /= N;
  // Standard errors for N(0,1): mean 1/sqrt(N), E z^2 sqrt(2/N), E z^3 sqrt(15/N),
  // E z^4 sqrt(96/N); bound |z-score| < 5.
  CHECK(std::abs(m1) < 5.0 / std::sqrt(N));
  CHECK(std::abs(m2 - 1.0) < 5.0 * std::sqrt(2.0 / N));
  CHECK(std::abs(m3) < 5.0 * std::sqrt(15.0 / N));
  CHECK(std::abs(m4 - 3.0) < 5.0 * std::sqrt(96.0 / N));
  CHECK(std::abs(s01 / n) < 5.0 / std::sqrt(static_cast<double>(n)));
  // Kolmogorov-Smirnov distance to the normal CDF (critical value 1.95/sqrt(N) at 0.1%).
  std::sort(z.begin(), z.end());
  double d = 0.0;
  for (std::size_t i = 0; i < z.size(); ++i) {
    const double F = 0.5 * std::erfc(-z[i] / std::sqrt(2.0));
    d = std::max({d, std::abs(F - static_cast<double>(i) / N), std::abs(F - static_cast<double>(i + 1) / N)});
  }
  CHECK(d < 1.95 / std::sqrt(N));
  // Tails: P(|z| > 3) = 0.0026998, binomial standard error.
  const auto tail = static_cast<double>(std::count_if(z.begin(), z.end(), [](double v) { return std::abs(v) > 3.0; }));
  const double p3 = 0.0026997960632601866;
  CHECK(std::abs(tail / N - p3) < 5.0 * std::sqrt(p3 * (1 - p3) / N));
}

TEST_CASE("kernel equals a scalar libm re-implementation on the same streams", "[simulator]") {
  // Three regimes: tiny per-partition angles, angles up to pi/4, and the
  // general path (a spot turn in 3 partitions).
  const std::vector<std::vector<WheelSegment>> paths{
      {{3.0, 1.0}},
      {{0.0, 2.0}, {1.0, -1.0}},
      {{-0.6, 0.6}, {2.0, 2.0}},
  };
  const std::vector<int> partitions{500, 8, 3};
  for (std::size_t c = 0; c < paths.size(); ++c) {
    const SimPlan plan = CompilePlan(BasicModel(0.4, 0.01, 0.02), paths[c], partitions[c]);
    std::vector<Pose2> out(21);
    SimulateFinalPoses(plan, 99, 5, 21, out.data());
    for (int i = 0; i < 21; ++i) {
      const Pose2 ref = ScalarReferenceRun(plan, 99, static_cast<std::uint64_t>(5 + i));
      CHECK(out[static_cast<std::size_t>(i)].x == Approx(ref.x).margin(1e-12));
      CHECK(out[static_cast<std::size_t>(i)].y == Approx(ref.y).margin(1e-12));
      CHECK(out[static_cast<std::size_t>(i)].theta == Approx(ref.theta).margin(1e-12));
    }
  }
}

TEST_CASE("zero noise reproduces the exact arc for any partition count", "[simulator]") {
  const std::vector<WheelSegment> path{{3.0, 1.0}, {-0.5, 0.5}, {2.0, 2.0}, {0.0, -1.2}};
  Pose2 exact{};
  for (const auto& s : path) exact = DiffDriveStep(exact, s.left_m, s.right_m, 0.4);
  for (int p : {1, 7, 1000}) {
    const SimPlan plan = CompilePlan(BasicModel(0.4, 0.0, 0.0), path, p);
    Pose2 out;
    SimulateFinalPoses(plan, 1, 0, 1, &out);
    CHECK(out.x == Approx(exact.x).margin(1e-12));
    CHECK(out.y == Approx(exact.y).margin(1e-12));
    CHECK(out.theta == Approx(exact.theta).margin(1e-12));
  }
}

TEST_CASE("true vs nominal parameters: E_d, E_b and scale follow the contract", "[simulator]") {
  SimulationModel m = BasicModel(0.34, 0.0, 0.0);
  m.truth.E_d = 1.004;
  m.truth.E_b = 1.02;
  const double b = 0.34;
  const auto square = ToWheelSegments(SquarePath(4.0, /*clockwise=*/true), b);
  const SimPlan plan = CompilePlan(m, square, 50);
  Pose2 out;
  SimulateFinalPoses(plan, 3, 0, 1, &out);
  // Independent reference: the calibration module's commanded square.
  const double c_L = 2.0 / (m.truth.E_d + 1.0), c_R = 2.0 / (1.0 / m.truth.E_d + 1.0);
  const Pose2 ref =
      ExecuteCommanded(CommandedSquare(SquareDirection::kCw, 4.0, b), b, m.truth.E_b, c_L, c_R);
  CHECK(out.x == Approx(ref.x).margin(1e-12));
  CHECK(out.y == Approx(ref.y).margin(1e-12));
  CHECK(out.theta == Approx(ref.theta).margin(1e-12));
  CHECK(plan.odometry_final.x == Approx(0.0).margin(1e-12));
  // scale_error: both wheels (1 + s) longer, straight line 1.5% further.
  SimulationModel ms = BasicModel(0.34, 0.0, 0.0);
  ms.truth.scale = 0.015;
  Pose2 line;
  SimulateFinalPoses(CompilePlan(ms, {{10.0, 10.0}}, 10), 3, 0, 1, &line);
  CHECK(line.x == Approx(10.15).epsilon(1e-13));
}

TEST_CASE("encoder quantisation: whole ticks, start phase, stop rule", "[simulator]") {
  SimulationModel m = BasicModel(0.4, 0.0, 0.0);
  m.nominal.ticks_per_rev = 100.0;  // 3.1416 mm per tick
  m.quantise_encoders = true;
  const double mpt = kPi * 0.1 / 100.0;
  const SimPlan plan = CompilePlan(m, {{1.0, 1.0}, {-1.0, -1.0}}, 20);
  // 1 m = 318.31 ticks -> target 318; back to 0.
  CHECK(plan.segments[0].ticks_left == 318);
  CHECK(plan.segments[1].ticks_left == 0);
  CHECK(plan.segments[0].odo_left_m == Approx(318 * mpt));
  CHECK(plan.odometry_final.x == Approx(0.0).margin(1e-15));
  // Forward stops at p = 318, backward just below p = 1: true travel 318 - phase, then -317.
  const auto traces = SimulateTraces(plan, 11, 0, 3, 20);
  for (const RunTrace& t : traces) {
    REQUIRE(t.truth.size() == 2);
    CHECK(t.phase_left >= 0.0);
    CHECK(t.phase_left < 1.0);
    const Pose2 p1 = DiffDriveStep(Pose2{}, (318 - t.phase_left) * mpt, (318 - t.phase_right) * mpt, 0.4);
    const Pose2 p2 = DiffDriveStep(p1, -317 * mpt, -317 * mpt, 0.4);
    CHECK(t.truth[0].x == Approx(p1.x).margin(1e-13));
    CHECK(t.truth[0].theta == Approx(p1.theta).margin(1e-13));
    CHECK(t.truth[1].x == Approx(p2.x).margin(1e-13));
    CHECK(t.truth[1].y == Approx(p2.y).margin(1e-13));
  }
  CHECK(traces[0].phase_left != traces[1].phase_left);
  // Encoder readings along a finely recorded trace: whole ticks of the
  // continuous wheel position (phase + true rotation / true metres per tick),
  // the targets at the segment ends.
  const auto fine = SimulateTraces(plan, 11, 0, 1, 1);
  const RunTrace& f = fine[0];
  REQUIRE(f.ticks_left.size() == 40);
  CHECK(f.ticks_left[19] == 318);
  CHECK(f.ticks_left[39] == 0);
  CHECK(f.wheel_left_m[19] == Approx(318 * mpt));
  for (std::size_t i = 0; i + 1 < 20; ++i) {
    const double pos = f.phase_left + (318 - f.phase_left) * static_cast<double>(i + 1) / 20.0;
    CHECK(f.ticks_left[i] == static_cast<std::int64_t>(std::floor(pos)));
  }
  CHECK(f.ticks_left[20] == static_cast<std::int64_t>(std::floor(318.0 - 317.0 / 20.0)));
  // Without quantisation the encoders report the commanded travel.
  const SimPlan smooth = CompilePlan(BasicModel(0.4, 0.01, 0.01), {{1.0, 1.0}, {-1.0, -1.0}}, 4);
  const RunTrace s = SimulateTraces(smooth, 1, 0, 1, 1)[0];
  CHECK(s.ticks_left.empty());
  CHECK(s.wheel_left_m[1] == Approx(0.5));
  CHECK(s.wheel_right_m[5] == Approx(0.5));
}

TEST_CASE("all SIMD kernels give identical bits", "[simulator]") {
  const SimPlan plan = CompilePlan(BasicModel(0.4, 0.01, 0.02), {{3.0, 1.0}, {0.0, 2.0}, {-0.6, 0.6}}, 50);
  const std::string best = SimKernelName();
  std::vector<Pose2> ref(37);
  SimulateFinalPoses(plan, 123, 3, 37, ref.data());
  for (const std::string& k : SimKernelsAvailable()) {
    REQUIRE(SelectSimKernel(k));
    std::vector<Pose2> out(37);
    SimulateFinalPoses(plan, 123, 3, 37, out.data());
    for (std::size_t i = 0; i < out.size(); ++i) {
      INFO("kernel " << k << " run " << i);
      CHECK(out[i].x == ref[i].x);
      CHECK(out[i].y == ref[i].y);
      CHECK(out[i].theta == ref[i].theta);
    }
  }
  REQUIRE(SelectSimKernel(best));
  CHECK_FALSE(SelectSimKernel("no-such-kernel"));
}

TEST_CASE("every run depends only on (seed, run index): lanes, blocks, threads", "[simulator]") {
  const SimPlan plan = CompilePlan(BasicModel(0.4, 0.003, 0.002), {{3.0, 1.0}}, 100);
  std::vector<Pose2> all(40), part(3);
  SimulateFinalPoses(plan, 5, 0, 40, all.data());
  SimulateFinalPoses(plan, 5, 17, 3, part.data());
  for (int i = 0; i < 3; ++i) {
    CHECK(part[static_cast<std::size_t>(i)].x == all[static_cast<std::size_t>(17 + i)].x);
    CHECK(part[static_cast<std::size_t>(i)].theta == all[static_cast<std::size_t>(17 + i)].theta);
  }
  // Traces end where the runs end.
  const auto tr = SimulateTraces(plan, 5, 17, 3, 10);
  CHECK(tr[1].truth.back().x == all[18].x);
  CHECK(tr[1].truth.size() == 10);
  // Different seeds differ.
  Pose2 other;
  SimulateFinalPoses(plan, 6, 17, 1, &other);
  CHECK(other.x != part[0].x);

  MonteCarloOptions o;
  o.runs = 1000;
  o.seed = 5;
  o.keep_runs = true;
  o.threads = 1;
  const MonteCarloSummary a = RunMonteCarlo(plan, o);
  o.threads = 3;
  const MonteCarloSummary b = RunMonteCarlo(plan, o);
  CHECK(a.mean.x == b.mean.x);
  CHECK(a.covariance(0, 2) == b.covariance(0, 2));
  CHECK(a.finals[17].x == all[17].x);
  CHECK(b.threads == 3);
  CHECK(a.steps_per_run == 100);
}

TEST_CASE("Monte Carlo covariance matches the closed form (z <= 4)", "[simulator]") {
  // Moderate noise so the first-order model holds: Table 1 case II with a
  // non-zero P0 and a mixed path.
  SimulationModel m = BasicModel(0.4, 0.003, 0.002);
  PoseCovariance P0;
  P0 << 0.0025, 0.0005, 0.0, 0.0005, 0.0025, 0.0002, 0.0, 0.0002, 0.0012;
  m.initial_covariance = P0;
  const std::vector<WheelSegment> path{{3.0, 1.0}, {2.0, 2.0}, {-0.4, 0.4}};
  const SimPlan plan = CompilePlan(m, path, 200);
  MonteCarloOptions o;
  o.runs = 20000;
  o.seed = 2024;
  const MonteCarloSummary mc = RunMonteCarlo(plan, o);
  const PathCovarianceSummary th = PredictPathCovariance(path, 0.4, m.noise, P0);
  const double n = static_cast<double>(o.runs);
  for (int i = 0; i < 3; ++i) {
    const double se_mean = std::sqrt(th.covariance(i, i) / n);
    const double mean_mc = i == 0 ? mc.mean.x : i == 1 ? mc.mean.y : mc.mean.theta;
    const double mean_th = i == 0 ? th.mean.x : i == 1 ? th.mean.y : th.mean.theta;
    CHECK(std::abs(mean_mc - mean_th) < 4.0 * se_mean);
    for (int j = i; j < 3; ++j) {
      // Normal-theory standard error of a sample covariance element.
      const double se = std::sqrt((th.covariance(i, i) * th.covariance(j, j) + std::pow(th.covariance(i, j), 2)) / n);
      INFO("element " << i << j << ": mc " << mc.covariance(i, j) << " theory " << th.covariance(i, j));
      CHECK(std::abs(mc.covariance(i, j) - th.covariance(i, j)) < 4.0 * se);
    }
  }
}
