// The numerics helpers (lib/stats: Boost.Math distributions, Brent, TOMS
// 748, NLopt's bounded minimiser) and the parallel-for, against published
// table values and closed forms.
#include <catch2/catch.hpp>

#include <atomic>
#include <cmath>
#include <limits>
#include <vector>

#include "core/parallel_for.hpp"
#include "stats/distributions.hpp"
#include "stats/optimize.hpp"

using namespace umbmark;

TEST_CASE("distributions match table values", "[stats]") {
  // Abramowitz & Stegun Table 26.1 / 26.7 / 26.8 (to the digits they print).
  CHECK(NormalQuantile(0.975) == Approx(1.959963984540054).epsilon(1e-14));
  CHECK(NormalCdf(1.0) == Approx(0.8413447460685429).epsilon(1e-14));
  CHECK(StudentTQuantile(0.975, 10.0) == Approx(2.228138851986274).epsilon(1e-12));
  CHECK(StudentTQuantile(0.995, 3.0) == Approx(5.840909309733350).epsilon(1e-12));
  CHECK(StudentTCdf(2.228138851986274, 10.0) == Approx(0.975).epsilon(1e-12));
  CHECK(ChiSquareQuantile(0.95, 1.0) == Approx(3.841458820694124).epsilon(1e-12));
  CHECK(ChiSquareQuantile(0.99, 2.0) == Approx(9.210340371976184).epsilon(1e-12));
  // chi^2 with 2 dof: survival exp(-x/2) exactly.
  CHECK(ChiSquareSurvival(3.0, 2.0) == Approx(std::exp(-1.5)).epsilon(1e-14));
  CHECK(ChiSquareSurvival(-1.0, 3.0) == 1.0);
  // I_x(a, 1) = x^a.
  CHECK(RegularizedIncompleteBeta(2.5, 1.0, 0.3) == Approx(std::pow(0.3, 2.5)).epsilon(1e-14));
  CHECK(std::isnan(NormalQuantile(0.0)));
  CHECK(std::isnan(StudentTQuantile(0.5, -1.0)));
}

TEST_CASE("binomial upper tail equals the sum of the probabilities", "[stats]") {
  const int n = 12;
  const double p = 0.3;
  for (int k = 0; k <= n + 1; ++k) {
    double sum = 0.0;
    for (int j = k; j <= n; ++j) sum += std::tgamma(n + 1.0) / (std::tgamma(j + 1.0) * std::tgamma(n - j + 1.0)) *
                                        std::pow(p, j) * std::pow(1.0 - p, n - j);
    CHECK(BinomialUpperTail(k, n, p) == Approx(std::min(1.0, sum)).epsilon(1e-12).margin(1e-300));
  }
}

TEST_CASE("Brent minimum, TOMS 748 root, bounded minimum", "[stats]") {
  const ScalarMinimum m = MinimizeBrent([](double x) { return (x - 2.0) * (x - 2.0) + 1.0; }, -5.0, 7.0);
  CHECK(m.x == Approx(2.0).margin(1e-9));
  CHECK(m.f == Approx(1.0).epsilon(1e-15));
  // Non-finite values count as +inf: the minimum stays on the finite side.
  const ScalarMinimum w = MinimizeBrent(
      [](double x) { return x < 0.0 ? std::numeric_limits<double>::quiet_NaN() : (x - 1.0) * (x - 1.0); }, -3.0, 4.0);
  CHECK(w.x == Approx(1.0).margin(1e-8));
  CHECK(FindRoot([](double x) { return x * x * x - 2.0; }, 0.0, 3.0, 1e-13) == Approx(std::cbrt(2.0)).epsilon(1e-12));
  // Decreasing bracket given high-to-low, and an infinite end.
  CHECK(FindRoot([](double x) { return x > 5.0 ? std::numeric_limits<double>::infinity() : x - 1.5; }, 9.0, 0.0,
                 1e-12) == Approx(1.5).epsilon(1e-11));
  // Rosenbrock with the box cutting off the minimum at (1, 1): x <= 0.5.
  const auto rosen = [](const std::vector<double>& x) {
    return 100.0 * std::pow(x[1] - x[0] * x[0], 2) + std::pow(1.0 - x[0], 2);
  };
  const BoundedMinimum b = MinimizeBounded(rosen, {-1.0, 2.0}, {-2.0, -2.0}, {0.5, 2.0});
  CHECK(b.converged);
  CHECK(b.x[0] == Approx(0.5).margin(1e-6));
  CHECK(b.x[1] == Approx(0.25).margin(1e-5));
  const BoundedMinimum u = MinimizeBounded(rosen, {-1.2, 1.0}, {-5.0, -5.0}, {5.0, 5.0});
  CHECK(u.x[0] == Approx(1.0).margin(1e-5));
  CHECK(u.x[1] == Approx(1.0).margin(1e-5));
}

TEST_CASE("parallel-for runs every item exactly once for any thread count", "[stats]") {
  for (const int threads : {0, 1, 3, 64}) {
    std::vector<std::atomic_int> hits(1000);
    ParallelFor(ResolveThreads(threads), std::int64_t{1000}, [&](std::int64_t i) { ++hits[static_cast<std::size_t>(i)]; });
    int wrong = 0;
    for (const auto& h : hits) wrong += h.load() != 1;
    CHECK(wrong == 0);
  }
  int calls = 0;
  ParallelFor(4, 0, [&](int) { ++calls; });
  CHECK(calls == 0);
}
