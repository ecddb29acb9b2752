// Distribution functions the library needs (confidence intervals, tests of
// fit), from Boost.Math: standard normal, Student t, chi-square and the
// binomial tail. Thin wrappers so callers do not spell Boost's policies, and
// domain errors come back as NaN instead of exceptions.
#pragma once

namespace umbmark {

/// Standard normal quantile: P(Z <= z) = p, for 0 < p < 1 (NaN otherwise).
double NormalQuantile(double p);

/// Standard normal CDF P(Z <= z).
double NormalCdf(double z);

/// Regularised incomplete beta function I_x(a, b), a, b > 0, 0 <= x <= 1.
double RegularizedIncompleteBeta(double a, double b, double x);

/// Student t cumulative distribution with `dof` > 0 degrees of freedom.
double StudentTCdf(double t, double dof);

/// Student t quantile: P(T <= t) = p, for 0 < p < 1 and dof > 0 (NaN otherwise).
double StudentTQuantile(double p, double dof);

/// Chi-square survival P(X > x) with `dof` > 0 degrees of freedom (1 for x <= 0).
double ChiSquareSurvival(double x, double dof);

/// Chi-square quantile: P(X <= x) = p, for 0 < p < 1 and dof > 0 (NaN otherwise).
double ChiSquareQuantile(double p, double dof);

/// Binomial upper tail P(K >= k) for K ~ Binomial(n, p), 0 <= p <= 1.
double BinomialUpperTail(int k, int n, double p);

}  // namespace umbmark
