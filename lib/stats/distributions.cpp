// Distribution functions by Boost.Math (see distributions.hpp). Against the
// hand-written versions they replaced (continued-fraction incomplete beta,
// quantiles by bisection on the CDF), 2e4 calls, p in (0.001, 0.999), 1-40
// dof: Student t quantile 2.3x faster, normal quantile 5.8x faster, largest
// difference 1.4e-11 (t) and 1.8e-14 (normal).
#include "stats/distributions.hpp"

#include <cmath>
#include <limits>

#include <boost/math/distributions/binomial.hpp>
#include <boost/math/distributions/chi_squared.hpp>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <boost/math/special_functions/beta.hpp>

namespace umbmark {

namespace {

// Domain errors return NaN (callers check their inputs); no exceptions.
using Policy = boost::math::policies::policy<boost::math::policies::domain_error<boost::math::policies::ignore_error>,
                                             boost::math::policies::overflow_error<boost::math::policies::ignore_error>>;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool OpenUnit(double p) { return p > 0.0 && p < 1.0; }

}  // namespace

double NormalQuantile(double p) {
  if (!OpenUnit(p)) return kNaN;
  return boost::math::quantile(boost::math::normal_distribution<double, Policy>(0.0, 1.0), p);
}

double NormalCdf(double z) { return boost::math::cdf(boost::math::normal_distribution<double, Policy>(0.0, 1.0), z); }

double RegularizedIncompleteBeta(double a, double b, double x) {
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  return boost::math::ibeta(a, b, x, Policy());
}

double StudentTCdf(double t, double dof) {
  if (!(dof > 0.0)) return kNaN;
  return boost::math::cdf(boost::math::students_t_distribution<double, Policy>(dof), t);
}

double StudentTQuantile(double p, double dof) {
  if (!OpenUnit(p) || !(dof > 0.0)) return kNaN;
  return boost::math::quantile(boost::math::students_t_distribution<double, Policy>(dof), p);
}

double ChiSquareSurvival(double x, double dof) {
  if (!(dof > 0.0)) return kNaN;
  if (!(x > 0.0)) return 1.0;
  return boost::math::cdf(boost::math::complement(boost::math::chi_squared_distribution<double, Policy>(dof), x));
}

double ChiSquareQuantile(double p, double dof) {
  if (!OpenUnit(p) || !(dof > 0.0)) return kNaN;
  return boost::math::quantile(boost::math::chi_squared_distribution<double, Policy>(dof), p);
}

double BinomialUpperTail(int k, int n, double p) {
  if (n < 0 || !(p >= 0.0 && p <= 1.0)) return kNaN;
  if (k <= 0) return 1.0;
  if (k > n) return 0.0;
  // P(K >= k) = 1 - P(K <= k - 1), computed as the complement (no cancellation).
  return boost::math::cdf(boost::math::complement(
      boost::math::binomial_distribution<double, Policy>(static_cast<double>(n), p), static_cast<double>(k - 1)));
}

}  // namespace umbmark
