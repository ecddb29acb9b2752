#include "planning/information.hpp"

#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "calibration/umbmark.hpp"
#include "model/true_robot.hpp"

namespace umbmark::planning {

Eigen::Matrix3d LeastSquaresTerms::Covariance() const {
  const Eigen::Matrix3d Ainv = A.completeOrthogonalDecomposition().pseudoInverse();
  return Ainv * B * Ainv;
}

namespace {

/// Odometry poses of `travel` under theta = [E_b, E_d, E_s].
std::vector<Pose2> OdometryAt(const WheelTravel& travel, double wheelbase_m, const Eigen::Vector3d& theta) {
  const double c_L = CorrectionLeft(theta(1)) * theta(2), c_R = CorrectionRight(theta(1)) * theta(2);
  WheelTravel scaled = travel;
  for (double& v : scaled.left_m) v *= c_L;
  for (double& v : scaled.right_m) v *= c_R;
  return IntegrateOdometry(scaled, wheelbase_m * theta(0), Pose2{});
}

}  // namespace

Eigen::MatrixXd OdometryJacobian(const WheelTravel& travel, double wheelbase_m) {
  const std::size_t n = travel.left_m.size();
  Eigen::MatrixXd J(2 * static_cast<Eigen::Index>(n), 3);
  constexpr double h = 1e-6;  // relative; central differences: error O(h^2) of a smooth map
  for (int p = 0; p < 3; ++p) {
    Eigen::Vector3d up = Eigen::Vector3d::Ones(), down = Eigen::Vector3d::Ones();
    up(p) += h;
    down(p) -= h;
    const std::vector<Pose2> a = OdometryAt(travel, wheelbase_m, up), b = OdometryAt(travel, wheelbase_m, down);
    for (std::size_t k = 0; k < n; ++k) {
      J(2 * static_cast<Eigen::Index>(k), p) = (a[k].x - b[k].x) / (2.0 * h);
      J(2 * static_cast<Eigen::Index>(k) + 1, p) = (a[k].y - b[k].y) / (2.0 * h);
    }
  }
  return J;
}

LeastSquaresTerms PathLeastSquaresTerms(const WheelTravel& travel, const std::vector<bool>& ground_truth,
                                        double wheelbase_m, const WheelNoise& noise, const GroundTruthModel& gt) {
  const std::size_t n = travel.left_m.size();
  LeastSquaresTerms out;
  if (n < 2) return out;
  const Eigen::MatrixXd J = OdometryJacobian(travel, wheelbase_m);
  const std::vector<Pose2> pose = IntegrateOdometry(travel, wheelbase_m, Pose2{});
  auto picked = [&](std::size_t k) { return k >= 1 && (ground_truth.empty() || ground_truth[k]); };
  auto Jt = [&](std::size_t k) -> Eigen::Matrix<double, 3, 2> {
    return J.block<2, 3>(2 * static_cast<Eigen::Index>(k), 0).transpose();
  };
  // Suffix sums over the picked samples after interval j: S1 = sum J_k',
  // S2 = sum J_k' (-y_k, x_k)'.
  Eigen::Matrix<double, 3, 2> S1 = Eigen::Matrix<double, 3, 2>::Zero();
  Eigen::Vector3d S2 = Eigen::Vector3d::Zero();
  const double qL = noise.k_L * noise.k_L, qR = noise.k_R * noise.k_R;
  for (std::size_t j = n - 1; j-- > 0;) {
    const std::size_t k = j + 1;
    if (picked(k)) {
      const Eigen::Matrix<double, 3, 2> Jk = Jt(k);
      out.A += Jk * Jk.transpose();
      S1 += Jk;
      S2 += Jk * Eigen::Vector2d(-pose[k].y, pose[k].x);
    }
    const double dL = travel.left_m[k] - travel.left_m[j], dR = travel.right_m[k] - travel.right_m[j];
    if (dL == 0.0 && dR == 0.0) continue;
    // Pose change of interval j per unit wheel travel error (world frame).
    const double mid = 0.5 * (pose[j].theta + pose[k].theta);
    Eigen::Matrix2d Bxy;
    Bxy << 0.5 * std::cos(mid), 0.5 * std::cos(mid), 0.5 * std::sin(mid), 0.5 * std::sin(mid);
    const Eigen::RowVector2d Bth(-1.0 / wheelbase_m, 1.0 / wheelbase_m);
    const Eigen::Matrix<double, 3, 2> G =
        S1 * Bxy + (S2 - S1 * Eigen::Vector2d(-pose[k].y, pose[k].x)) * Bth;
    out.B += G * Eigen::Vector2d(qL * std::abs(dL), qR * std::abs(dR)).asDiagonal() * G.transpose();
  }
  // The ground truth's white noise at every picked sample, and the first
  // sample's, which sets the frame: dg_k = -n0 + m0 (y_k, -x_k).
  const double sxy2 = gt.sigma_xy_m * gt.sigma_xy_m, sth2 = gt.sigma_theta_rad * gt.sigma_theta_rad;
  out.B += sxy2 * out.A;
  out.B += sxy2 * S1 * S1.transpose() + sth2 * S2 * S2.transpose();  // w = sum J_k'(y_k, -x_k)' = -S2
  return out;
}

Eigen::Matrix2d ClassicCovariance(const Eigen::Matrix2d& run_cov_cw, int n_cw, const Eigen::Matrix2d& run_cov_ccw,
                                  int n_ccw, double side_m, double wheelbase_m) {
  // (E_d, E_b) of the mean estimator from c = (x_cw, y_cw, x_ccw, y_ccw).
  auto estimate = [&](const Eigen::Vector4d& c) {
    const UmbmarkEstimate ex = EstimateFromCentres(c(0), c(2), true, side_m, wheelbase_m, true);
    const UmbmarkEstimate ey = EstimateFromCentres(c(1), c(3), false, side_m, wheelbase_m, true);
    return Eigen::Vector2d(0.5 * (ex.E_d + ey.E_d), 0.5 * (ex.E_b + ey.E_b));
  };
  const double h = 1e-6 * side_m;  // return errors of a micrometre per metre of side: linear regime
  Eigen::Matrix<double, 2, 4> G;
  for (int i = 0; i < 4; ++i) {
    Eigen::Vector4d up = Eigen::Vector4d::Zero(), down = Eigen::Vector4d::Zero();
    up(i) = h;
    down(i) = -h;
    G.col(i) = (estimate(up) - estimate(down)) / (2.0 * h);
  }
  Eigen::Matrix4d C = Eigen::Matrix4d::Zero();
  C.topLeftCorner<2, 2>() = run_cov_cw / std::max(n_cw, 1);
  C.bottomRightCorner<2, 2>() = run_cov_ccw / std::max(n_ccw, 1);
  return G * C * G.transpose();
}

Eigen::Matrix2d RunNoiseInformation(const CovarianceBasis& basis, const Eigen::Matrix3d& measurement,
                                    const WheelNoise& noise) {
  const Eigen::Matrix3d S = basis.Evaluate(noise) + measurement;
  Eigen::LDLT<Eigen::Matrix3d> ldlt(S);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) return Eigen::Matrix2d::Zero();
  const Eigen::Matrix3d SL = ldlt.solve(basis.A_L), SR = ldlt.solve(basis.A_R);
  Eigen::Matrix2d I;
  I(0, 0) = 0.5 * (SL * SL).trace();
  I(1, 1) = 0.5 * (SR * SR).trace();
  I(0, 1) = I(1, 0) = 0.5 * (SL * SR).trace();
  return I;
}

Eigen::Matrix2d NoiseInformation(const std::vector<NoiseRunModel>& runs, const WheelNoise& noise) {
  std::vector<std::pair<std::string, double>> groups;
  auto total = [&](const std::string& g) -> double& {
    for (auto& [name, n] : groups)
      if (name == g) return n;
    groups.emplace_back(g, 0.0);
    return groups.back().second;
  };
  for (const NoiseRunModel& r : runs) total(r.group) += r.count;
  Eigen::Matrix2d I = Eigen::Matrix2d::Zero();
  for (const NoiseRunModel& r : runs) {
    const double n_g = total(r.group);
    if (n_g < 2.0 || r.count <= 0.0) continue;
    I += r.count * (n_g - 1.0) / n_g * RunNoiseInformation(r.basis, r.measurement, noise);
  }
  return I;
}

Eigen::Vector2d NoiseHalfWidths(const Eigen::Matrix2d& information, const WheelNoise& noise) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  const double det = information.determinant();
  if (!(det > 1e-12 * information.diagonal().prod()) || !std::isfinite(det)) return {inf, inf};
  const Eigen::Matrix2d cov = information.inverse();
  auto half = [&](int i, double k) { return k > 0.0 ? kZ95 * std::sqrt(cov(i, i)) / (2.0 * k) : inf; };
  return {half(0, noise.k_L), half(1, noise.k_R)};
}

}  // namespace umbmark::planning
