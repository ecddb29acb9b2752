// Chong & Kleeman's random wheel error model (eq. 4): each wheel's travel
// error is zero-mean white noise whose variance grows with the distance that
// wheel rolls, sigma_L^2 = k_L^2 |d_L|, sigma_R^2 = k_R^2 |d_R| (k in m^1/2).
// Because the pose covariance produced by this noise is linear in k_L^2 and
// k_R^2, every propagation routine returns a CovarianceBasis (the covariance
// per unit k^2 of each wheel), which fitting code reuses for any k.
#pragma once

#include <cmath>
#include <string>

#include <Eigen/Core>
#include <fmt/format.h>

namespace umbmark {

/// Pose covariance over [x, y, theta] (m, m, rad), row-major as printed.
using PoseCovariance = Eigen::Matrix3d;

struct WheelNoise {
  /// Left / right wheel noise constants k_L, k_R [m^1/2], eq. (4). >= 0.
  double k_L = 0.0;
  double k_R = 0.0;

  /// Empty when valid, else a message naming the bad field.
  std::string Check() const {
    if (!std::isfinite(k_L) || k_L < 0.0) return fmt::format("k_L = {} must be a finite number >= 0", k_L);
    if (!std::isfinite(k_R) || k_R < 0.0) return fmt::format("k_R = {} must be a finite number >= 0", k_R);
    return {};
  }
};

/// Motion covariance Cov(U) = k_L^2 A_L + k_R^2 A_R (eq. 23, second term):
/// A_L is the pose covariance caused by unit left-wheel noise (k_L = 1,
/// k_R = 0), A_R likewise for the right wheel.
struct CovarianceBasis {
  PoseCovariance A_L = PoseCovariance::Zero();
  PoseCovariance A_R = PoseCovariance::Zero();

  PoseCovariance Evaluate(const WheelNoise& noise) const {
    return noise.k_L * noise.k_L * A_L + noise.k_R * noise.k_R * A_R;
  }
  CovarianceBasis& operator+=(const CovarianceBasis& o) {
    A_L += o.A_L;
    A_R += o.A_R;
    return *this;
  }
};

}  // namespace umbmark
