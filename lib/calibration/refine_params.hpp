// Parameterisation of the refined calibration (calibrate --refine), shared
// by its API (refine.hpp) and its residuals (refine_residuals.hpp). One
// parameter block theta = [E_b, E_d, E_s], all relative to a REFERENCE robot
// (the recorded parameters the summary reports against):
//
//   E_b = b_true / b_ref                                   (eq. 2.4, relative)
//   E_d = (D_R / D_L)_true / (D_R / D_L)_ref               (eq. 2.3, relative)
//   E_s = (c_L + c_R) / 2  (Borenstein & Feng's scaling error, section 2.2)
//   c_L = 2 E_s / (E_d + 1)    = D_L,true / D_L,ref        (eq. 4.31 times E_s)
//   c_R = 2 E_s / (1/E_d + 1)  = D_R,true / D_R,ref        (eq. 4.32 times E_s)
//
// With E_s = 1 this is exactly the classic UMBmark correction (mean of the
// two factors kept), so fixing E_s fixes the unobservable overall scale.
// All three are dimensionless and close to 1, which makes the Jacobian's
// columns directly comparable (identifiability report).
#pragma once

#include <cmath>
#include <optional>
#include <string_view>

#include <ceres/jet.h>  // Jet only; no glog (whose CHECK clashes with Catch's)

namespace umbmark {

/// Index of each unknown in theta.
enum RefineIndex : int { kIndexEb = 0, kIndexEd = 1, kIndexEs = 2, kNumRefineParameters = 3 };

/// Wheel factors from theta (eqs. 4.31, 4.32, scaled by E_s).
template <typename T>
void WheelFactors(const T* theta, T* c_L, T* c_R) {
  const T& E_d = theta[kIndexEd];
  const T& E_s = theta[kIndexEs];
  *c_L = T(2.0) * E_s / (E_d + T(1.0));
  *c_R = T(2.0) * E_s * E_d / (E_d + T(1.0));
}

/// The double part of a scalar (for branch decisions that must not be
/// differentiated, such as choosing a 2*pi branch).
inline double ScalarPart(double v) { return v; }
template <typename T, int N>
double ScalarPart(const ceres::Jet<T, N>& v) {
  return ScalarPart(v.a);
}

/// Robust losses applied per sampled pose of a trajectory (see below).
enum class RobustLoss { kNone, kHuber, kCauchy };
const char* RobustLossToString(RobustLoss l);
std::optional<RobustLoss> RobustLossFromString(std::string_view s);

/// Per-sample robust reweighting. Ceres applies a LossFunction to a whole
/// residual block, but one trajectory block holds every sampled pose of a
/// run (integrating the run once is what keeps the fit O(samples)). So the
/// loss is applied inside the block, per pose: the pose residual r (3-vector,
/// metres) becomes r * sqrt(rho(s) / s) with s = |r|^2, whose squared norm is
/// exactly rho(s). The objective is therefore exactly the robust one,
/// sum rho(|r_k|^2) / 2; only the Gauss-Newton curvature differs from Ceres'
/// Triggs correction (same minimum). rho as in ceres/loss_function.h, with
/// scale a [m]:  Huber  rho = s (s <= a^2), 2 a sqrt(s) - a^2 (s > a^2);
///               Cauchy rho = a^2 log(1 + s / a^2).
template <typename T>
T RobustFactor(const T& s, RobustLoss loss, double a) {
  using std::log1p;
  using std::sqrt;
  const double a2 = a * a;
  switch (loss) {
    case RobustLoss::kNone: return T(1.0);
    case RobustLoss::kHuber: {
      if (ScalarPart(s) <= a2) return T(1.0);
      const T root = sqrt(s);
      return sqrt(T(2.0 * a) / root - T(a2) / s);
    }
    case RobustLoss::kCauchy: {
      const T x = s / T(a2);
      if (ScalarPart(x) < 1e-8) return sqrt(T(1.0) - x / T(2.0) + x * x / T(3.0));  // log1p(x)/x series
      return sqrt(log1p(x) / x);
    }
  }
  return T(1.0);
}

}  // namespace umbmark
