// One-dimensional minimisation and root finding (Boost.Math: Brent's
// minimiser, TOMS 748 root finder) and bounded derivative-free
// minimisation in several variables (NLopt). Callers pass plain callables;
// non-finite function values are allowed (treated as "very large").
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace umbmark {

/// Result of a one-dimensional minimisation.
struct ScalarMinimum {
  double x = 0.0;
  double f = 0.0;
};

/// Minimum of f on [a, b] by Brent's method (parabolic interpolation with
/// golden-section fallback; Brent 1973, ch. 5), to about 2^-bits relative
/// precision in x (bits <= 52; Boost's brent_find_minima). Non-finite values
/// of f count as +inf.
ScalarMinimum MinimizeBrent(const std::function<double(double)>& f, double a, double b, int bits = 40);

/// A root of f in [a, b] where f(a) and f(b) have opposite signs (or one is
/// 0), to an absolute bracket width `tol` in x (TOMS 748, Alefeld, Potra &
/// Shi 1995; Boost's toms748_solve). Non-finite values of f are handled by
/// bisection steps. Returns the bracket end with the smaller |f|.
double FindRoot(const std::function<double(double)>& f, double a, double b, double tol, int max_iterations = 100);

/// Options of MinimizeBounded.
struct BoundedMinimizeOptions {
  /// Relative tolerance on x (NLopt xtol_rel). Default 1e-8.
  double x_tolerance = 1e-8;
  /// Relative tolerance on f (NLopt ftol_rel). Default 1e-12.
  double f_tolerance = 1e-12;
  /// Evaluation limit (>= 1). Default 2000.
  int max_evaluations = 2000;
  /// Initial step per variable; empty: 10% of each box width (or 0.1 when unbounded).
  std::vector<double> initial_step;
};

/// Result of MinimizeBounded.
struct BoundedMinimum {
  std::vector<double> x;
  double f = 0.0;
  int evaluations = 0;
  bool converged = false;  ///< a tolerance was met (not the evaluation limit)
  std::string message;     ///< NLopt's result code in words
};

/// Minimum of f over the box lower <= x <= upper (bounds may be +-inf)
/// from `start` (clamped into the box), by NLopt's Sbplx (Rowan's subplex:
/// Nelder-Mead on subspaces with real bounds; derivative-free). Non-finite
/// values of f count as +inf.
BoundedMinimum MinimizeBounded(const std::function<double(const std::vector<double>&)>& f, std::vector<double> start,
                               const std::vector<double>& lower, const std::vector<double>& upper,
                               const BoundedMinimizeOptions& options = {});

}  // namespace umbmark
