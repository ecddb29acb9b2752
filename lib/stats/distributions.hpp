// Quantiles the refined calibration needs for its confidence intervals:
// standard normal and Student t (for covariances estimated from a handful of
// runs). Pure functions, no dependencies beyond <cmath>.
#pragma once

namespace umbmark {

/// Standard normal quantile: P(Z <= z) = p, for 0 < p < 1 (|error| < 1e-12).
double NormalQuantile(double p);

/// Regularised incomplete beta function I_x(a, b), a, b > 0, 0 <= x <= 1.
double RegularizedIncompleteBeta(double a, double b, double x);

/// Student t cumulative distribution with `dof` > 0 degrees of freedom.
double StudentTCdf(double t, double dof);

/// Student t quantile: P(T <= t) = p, for 0 < p < 1 and dof > 0.
double StudentTQuantile(double p, double dof);

}  // namespace umbmark
