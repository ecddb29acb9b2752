// Closed-form and quadrature motion covariance of a constant-curvature arc
// (Chong & Kleeman eq. 25); see covariance_arc.hpp.
#include "error_models/covariance_arc.hpp"

#include <array>
#include <cmath>

#include "kinematics/diff_drive.hpp"

namespace umbmark {
namespace {

/// Gauss-Legendre nodes/weights on [0, 1], computed once by Newton iteration
/// on the Legendre recursion (n = 12: exact for polynomials of degree 23).
constexpr int kGaussNodes = 12;
struct GaussLegendre {
  std::array<double, kGaussNodes> u{}, w{};
  GaussLegendre() {
    const int n = kGaussNodes;
    for (int i = 0; i < n; ++i) {
      double x = std::cos(kPi * (i + 0.75) / (n + 0.5));
      double dp = 0.0;
      for (int it = 0; it < 100; ++it) {
        double p0 = 1.0, p1 = x;
        for (int k = 2; k <= n; ++k) {
          const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        dp = n * (x * p1 - p0) / (x * x - 1.0);
        const double dx = p1 / dp;
        x -= dx;
        if (std::abs(dx) < 1e-17) break;
      }
      u[i] = 0.5 * (1.0 - x);
      w[i] = 1.0 / ((1.0 - x * x) * dp * dp);  // 2/((1-x^2) P'^2) on [-1,1], halved for [0,1]
    }
  }
};

const GaussLegendre& Nodes() {
  static const GaussLegendre gl;
  return gl;
}

}  // namespace

CovarianceBasis ArcCovarianceBasisClosedForm(double L, double R, double theta0, double B) {
  const double thk = theta0 + (R - L) / B;      // (14)
  const double r = 0.5 * B * (L + R) / (L - R);  // (15)
  const double dLR = L - R;
  const double d2 = dLR * dLR, d3 = d2 * dLR;
  const double s0 = std::sin(theta0), c0 = std::cos(theta0), sk = std::sin(thk), ck = std::cos(thk);
  const double dth = thk - theta0;
  const double s20 = std::sin(2.0 * theta0), s2k = std::sin(2.0 * thk);
  const double c20 = std::cos(2.0 * theta0), c2k = std::cos(2.0 * thk);
  const double rb = r / B;

  // Eq. (25): every element is f1*S1 + f0*S0 + f2*S2 with
  //   S1 = k_R^2 |R| L + k_L^2 R |L|,  S0 = k_R^2 |R| + k_L^2 |L|,
  //   S2 = k_R^2 L^2 |R| + k_L^2 R^2 |L|.
  struct F {
    double f1, f0, f2;
  };
  const double g = -B / (4.0 * d3);
  const F e11{-2.0 * r / d2 * (s0 - sk) * ck, rb * ck * rb * ck, g * (2.0 * dth - s20 + s2k)};
  const F e22{-2.0 * r / d2 * (ck - c0) * sk, rb * sk * rb * sk, g * (2.0 * dth + s20 - s2k)};
  const F e33{0.0, 1.0 / (B * B), 0.0};
  const F e12{-r / d2 * (c2k - std::cos(theta0 + thk)), 0.5 * rb * rb * s2k, g * (c20 - c2k)};
  const F e13{1.0 / d2 * (s0 - sk), -r / (B * B) * ck, 0.0};
  const F e23{1.0 / d2 * (ck - c0), -r / (B * B) * sk, 0.0};

  auto fill = [&](double S1, double S0, double S2) {
    auto v = [&](const F& f) { return f.f1 * S1 + f.f0 * S0 + f.f2 * S2; };
    PoseCovariance P;
    P(0, 0) = v(e11);
    P(1, 1) = v(e22);
    P(2, 2) = v(e33);
    P(0, 1) = P(1, 0) = v(e12);
    P(0, 2) = P(2, 0) = v(e13);
    P(1, 2) = P(2, 1) = v(e23);
    return P;
  };
  CovarianceBasis b;
  const double aL = std::abs(L), aR = std::abs(R);
  b.A_L = fill(R * aL, aL, R * R * aL);  // k_L = 1, k_R = 0
  b.A_R = fill(aR * L, aR, L * L * aR);  // k_L = 0, k_R = 1
  return b;
}

CovarianceBasis ArcCovarianceBasisQuadrature(double L, double R, double theta0, double B) {
  const GaussLegendre& gl = Nodes();
  const double dth = (R - L) / B;
  const double S = 0.5 * (L + R);  // path length of the axle midpoint (signed)
  CovarianceBasis b;
  for (int i = 0; i < kGaussNodes; ++i) {
    const double u = gl.u[i];
    const double v = 1.0 - u;
    const double th = theta0 + u * dth;
    // Chord from the point at u to the end: length S v sinc(v dth/2), direction
    // th + v dth/2 (the stable form of x1 - x(u), y1 - y(u)).
    const double chord = S * v * Sinc(0.5 * v * dth);
    const double dir = th + 0.5 * v * dth;
    const double dx = chord * std::cos(dir), dy = chord * std::sin(dir);
    const double c = std::cos(th), s = std::sin(th);
    const Eigen::Vector3d jl(0.5 * c + dy / B, 0.5 * s - dx / B, -1.0 / B);
    const Eigen::Vector3d jr(0.5 * c - dy / B, 0.5 * s + dx / B, 1.0 / B);
    b.A_L += (gl.w[i] * std::abs(L)) * (jl * jl.transpose());
    b.A_R += (gl.w[i] * std::abs(R)) * (jr * jr.transpose());
  }
  return b;
}

CovarianceBasis ArcCovarianceBasis(double L, double R, double theta0, double B) {
  if (std::abs(R - L) < kArcQuadratureBelowRad * B) return ArcCovarianceBasisQuadrature(L, R, theta0, B);
  return ArcCovarianceBasisClosedForm(L, R, theta0, B);
}

}  // namespace umbmark
