// Brent, TOMS 748 (Boost.Math) and Sbplx (NLopt) behind plain callables
// (see optimize.hpp).
#include "stats/optimize.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <boost/math/tools/minima.hpp>
#include <boost/math/tools/roots.hpp>
#include <nlopt.hpp>

namespace umbmark {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double Finite(double v) { return std::isfinite(v) ? v : kInf; }

}  // namespace

ScalarMinimum MinimizeBrent(const std::function<double(double)>& f, double a, double b, int bits) {
  std::uintmax_t iterations = 200;
  const auto r = boost::math::tools::brent_find_minima([&](double x) { return Finite(f(x)); }, a, b,
                                                      std::clamp(bits, 4, 52), iterations);
  return {r.first, r.second};
}

double FindRoot(const std::function<double(double)>& f, double a, double b, double tol, int max_iterations) {
  double fa = f(a), fb = f(b);
  // Bisect until both ends are finite: TOMS 748 interpolates through them.
  int it = 0;
  for (; it < max_iterations && (!std::isfinite(fa) || !std::isfinite(fb)) && std::abs(b - a) > tol; ++it) {
    const double c = 0.5 * (a + b), fc = f(c);
    if (!std::isfinite(fc) || (fc > 0.0) == (fb > 0.0) || fc == 0.0) {
      if (!std::isfinite(fb) || (std::isfinite(fc) && (fc > 0.0) == (fb > 0.0))) b = c, fb = fc;
      else a = c, fa = fc;
    } else {
      a = c, fa = fc;
    }
  }
  if (fa == 0.0) return a;
  if (fb == 0.0) return b;
  if (!std::isfinite(fa) || !std::isfinite(fb) || (fa > 0.0) == (fb > 0.0)) return std::abs(fa) < std::abs(fb) ? a : b;
  const bool ascending = a < b;
  double lo = ascending ? a : b, hi = ascending ? b : a;
  double flo = ascending ? fa : fb, fhi = ascending ? fb : fa;
  std::uintmax_t left = static_cast<std::uintmax_t>(std::max(1, max_iterations - it));
  const auto r = boost::math::tools::toms748_solve(
      [&](double x) {
        const double v = f(x);
        return std::isfinite(v) ? v : (fhi > 0.0 ? kInf : -kInf);
      },
      lo, hi, flo, fhi, [tol](double u, double v) { return std::abs(v - u) <= tol; }, left);
  const double fl = f(r.first), fh = f(r.second);
  return std::abs(fl) < std::abs(fh) ? r.first : r.second;
}

BoundedMinimum MinimizeBounded(const std::function<double(const std::vector<double>&)>& f, std::vector<double> start,
                               const std::vector<double>& lower, const std::vector<double>& upper,
                               const BoundedMinimizeOptions& options) {
  const std::size_t n = start.size();
  nlopt::opt opt(nlopt::LN_SBPLX, static_cast<unsigned>(n));
  opt.set_lower_bounds(lower);
  opt.set_upper_bounds(upper);
  opt.set_xtol_rel(options.x_tolerance);
  opt.set_ftol_rel(options.f_tolerance);
  opt.set_maxeval(std::max(1, options.max_evaluations));
  std::vector<double> step = options.initial_step;
  if (step.size() != n) {
    step.assign(n, 0.1);
    for (std::size_t i = 0; i < n; ++i)
      if (std::isfinite(lower[i]) && std::isfinite(upper[i]) && upper[i] > lower[i]) step[i] = 0.1 * (upper[i] - lower[i]);
  }
  opt.set_initial_step(step);
  for (std::size_t i = 0; i < n; ++i) start[i] = std::clamp(start[i], lower[i], upper[i]);
  BoundedMinimum out;
  auto objective = [&](const std::vector<double>& x) {
    ++out.evaluations;
    return Finite(f(x));
  };
  using Objective = decltype(objective);
  const auto trampoline = [](unsigned, const double* x, double*, void* data) -> double {
    auto* self = static_cast<std::pair<Objective*, std::size_t>*>(data);
    return (*self->first)(std::vector<double>(x, x + self->second));
  };
  std::pair<Objective*, std::size_t> data{&objective, n};
  opt.set_min_objective(trampoline, &data);
  double fmin = kInf;
  nlopt::result result = nlopt::FAILURE;
  try {
    result = opt.optimize(start, fmin);
  } catch (const std::exception& e) {  // NLopt reports roundoff-limited and forced stops by exceptions
    out.message = e.what();
  }
  out.x = start;
  out.f = fmin;
  out.converged = result == nlopt::SUCCESS || result == nlopt::FTOL_REACHED || result == nlopt::XTOL_REACHED ||
                  result == nlopt::STOPVAL_REACHED;
  if (out.message.empty()) {
    switch (result) {
      case nlopt::MAXEVAL_REACHED: out.message = "evaluation limit reached"; break;
      case nlopt::FTOL_REACHED: out.message = "f tolerance reached"; break;
      case nlopt::XTOL_REACHED: out.message = "x tolerance reached"; break;
      default: out.message = "NLopt result " + std::to_string(static_cast<int>(result)); break;
    }
  }
  return out;
}

}  // namespace umbmark
