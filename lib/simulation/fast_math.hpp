// Branch-free elementary functions for the simulator's hot loop, written so
// that GCC/Clang vectorise them across SIMD lanes (no tables, no branches,
// no libm calls except std::fma, which is one instruction on FMA hardware)
// and give the same bits in scalar and vector code.
//
// Polynomials: the kernels of fdlibm (Sun Microsystems, freely
// redistributable) for ln on [sqrt(1/2), sqrt(2)) and sin/cos on
// [-pi/4, pi/4] (errors below 1 ulp before the final rounding), and short
// Taylor polynomials for the tiny per-partition turning angles.
// tests/test_simulator.cpp checks every function against libm over its
// domain. Outside the stated domains the results are wrong; callers
// guarantee the domains.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>

namespace umbmark::sim::fm {

inline constexpr double kPi = 3.14159265358979323846;

/// a * b + c with one rounding (a single instruction on FMA hardware).
inline double Fma(double a, double b, double c) { return std::fma(a, b, c); }

/// [1, 2) from the 52 high bits of a random word.
inline double One52(std::uint64_t bits) {
  return std::bit_cast<double>((bits >> 12) | 0x3FF0000000000000ull);
}
/// [0, 1) with 52 random bits.
inline double Unit52(std::uint64_t bits) { return One52(bits) - 1.0; }

/// Flips the sign of x when flip == 1.
inline double FlipSign(double x, std::uint64_t flip) {
  return std::bit_cast<double>(std::bit_cast<std::uint64_t>(x) ^ (flip << 63));
}

/// sqrt(x) for 0 <= x < 2^1000, branch-free (std::sqrt may set errno, which
/// stops vectorisation): reciprocal square root from the exponent trick
/// (error < 3.5%), three Newton steps (error ~3e-11), then one Newton step
/// on the square root itself; within 1 ulp of the correctly rounded value.
inline double Sqrt(double x) {
  const double xs = x > 1e-300 ? x : 1e-300;  // sqrt(0) = 0 * finite
  double y = std::bit_cast<double>(0x5FE6EB50C7B537A9ull - (std::bit_cast<std::uint64_t>(xs) >> 1));
  const double hx = 0.5 * xs;
  y = y * Fma(-hx * y, y, 1.5);
  y = y * Fma(-hx * y, y, 1.5);
  y = y * Fma(-hx * y, y, 1.5);
  const double r = x * y;
  return Fma(0.5 * y, Fma(-r, r, x), r);
}

/// ln(u) for normal u in (0, 1]: u = 2^e (1 + f), 1 + f in [sqrt(1/2),
/// sqrt(2)); ln(1 + f) = f - f^2/2 + s (f^2/2 + R(s^2)), s = f / (2 + f)
/// (fdlibm e_log.c).
inline double LogUnit(double u) {
  constexpr double kLn2Hi = 6.93147180369123816490e-01, kLn2Lo = 1.90821492927058770002e-10;
  constexpr double Lg1 = 6.666666666666735130e-01, Lg2 = 3.999999999940941908e-01,
                   Lg3 = 2.857142874366239149e-01, Lg4 = 2.222219843214978396e-01,
                   Lg5 = 1.818357216161805012e-01, Lg6 = 1.531383769920937332e-01,
                   Lg7 = 1.479819860511658591e-01;
  const std::uint64_t bits = std::bit_cast<std::uint64_t>(u);
  double m = std::bit_cast<double>((bits & 0x000FFFFFFFFFFFFFull) | 0x3FF0000000000000ull);
  // Unbiased exponent as a double without an int->double conversion.
  double e = std::bit_cast<double>((bits >> 52) | 0x4330000000000000ull) - (4503599627370496.0 + 1023.0);
  const bool big = m > 1.4142135623730951;
  m = big ? 0.5 * m : m;
  e = big ? e + 1.0 : e;
  const double f = m - 1.0;
  const double s = f / (2.0 + f);
  const double z = s * s, w = z * z;
  const double t1 = w * Fma(w, Fma(w, Lg6, Lg4), Lg2);
  const double t2 = z * Fma(w, Fma(w, Fma(w, Lg7, Lg5), Lg3), Lg1);
  const double R = t2 + t1;
  const double hfsq = 0.5 * f * f;
  return Fma(e, kLn2Hi, -((hfsq - Fma(s, hfsq + R, e * kLn2Lo)) - f));
}

/// sin and cos of |a| <= pi/4 (fdlibm k_sin.c / k_cos.c without the tail
/// argument).
inline void SinCosQuarter(double a, double& s, double& c) {
  constexpr double S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03,
                   S3 = -1.98412698298579493134e-04, S4 = 2.75573137070700676789e-06,
                   S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
  constexpr double C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03,
                   C3 = 2.48015872894767294178e-05, C4 = -2.75573143513906633035e-07,
                   C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;
  const double z = a * a;
  const double rs = Fma(z, Fma(z, Fma(z, Fma(z, S6, S5), S4), S3), S2);
  s = Fma(a * z, Fma(z, rs, S1), a);
  const double rc = z * Fma(z, Fma(z, Fma(z, Fma(z, Fma(z, C6, C5), C4), C3), C2), C1);
  // cos = 1 - z/2 + z^2 rc, evaluated as fdlibm does for |a| < 0.3 and
  // with the split w = 1 - hz, 1 - w - hz for the larger arguments.
  const double hz = 0.5 * z;
  const double w = 1.0 - hz;
  c = w + (((1.0 - w) - hz) + z * rc);
}

/// sin(a)/a and cos(a) for |a| <= 1/16 (Taylor; truncation < 3e-19).
inline void SincCosTiny(double a, double& sinc, double& c) {
  const double z = a * a;
  sinc = Fma(z, Fma(z, Fma(z, Fma(z, 1.0 / 362880.0, -1.0 / 5040.0), 1.0 / 120.0), -1.0 / 6.0), 1.0);
  c = Fma(z, Fma(z, Fma(z, Fma(z, 1.0 / 40320.0, -1.0 / 720.0), 1.0 / 24.0), -0.5), 1.0);
}

/// sin(a)/a and cos(a) for |a| <= pi/4.
inline void SincCosQuarter(double a, double& sinc, double& c) {
  constexpr double S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03,
                   S3 = -1.98412698298579493134e-04, S4 = 2.75573137070700676789e-06,
                   S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
  const double z = a * a;
  sinc = Fma(z, Fma(z, Fma(z, Fma(z, Fma(z, Fma(z, S6, S5), S4), S3), S2), S1), 1.0);
  double s;
  SinCosQuarter(a, s, c);
}

}  // namespace umbmark::sim::fm
