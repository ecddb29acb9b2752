// The lidar's mount from scans and wheels (see mount_check.hpp).
#include "scan/mount_check.hpp"

#include <cmath>

#include <Eigen/Dense>

namespace umbmark::scan {

Pose2 LidarMotionFromAxle(const Pose2& mount, const Pose2& axle_motion) {
  return Compose(Compose(Inverse(mount), axle_motion), mount);
}

MountEstimate EstimateMount(const std::vector<MountPair>& pairs) {
  MountEstimate e;
  double ll = 0.0, aa = 0.0, travel = 0.0;
  for (const auto& p : pairs) {
    ll += p.lidar.theta * p.axle.theta;
    aa += p.axle.theta * p.axle.theta;
    travel += std::hypot(p.axle.x, p.axle.y);
    e.turned_rad += std::abs(p.axle.theta);
  }
  e.straight_m = travel;
  if (pairs.size() < 3 || travel < 0.3) return e;
  e.turn_ratio = aa > 1e-9 ? ll / aa : 1.0;
  e.mirrored = e.turn_ratio < 0.0;
  // Normal equations of R(phi) t_L + (I - R(theta_A)) m = t_A in u = (c, s, m_x, m_y).
  Eigen::Matrix4d n = Eigen::Matrix4d::Zero();
  Eigen::Vector4d b = Eigen::Vector4d::Zero();
  for (const auto& p : pairs) {
    const double lx = p.lidar.x, ly = e.mirrored ? -p.lidar.y : p.lidar.y;
    const double ca = std::cos(p.axle.theta), sa = std::sin(p.axle.theta);
    Eigen::Matrix<double, 2, 4> j;
    j << lx, -ly, 1.0 - ca, sa,  //
        ly, lx, -sa, 1.0 - ca;
    n += j.transpose() * j;
    b += j.transpose() * Eigen::Vector2d(p.axle.x, p.axle.y);
  }
  // The position rests on the turns: without them its block is singular, and
  // the yaw is solved from the straight motion alone.
  const Eigen::Matrix2d nm = n.block<2, 2>(2, 2);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(nm);
  e.position_determined = es.eigenvalues()(0) > 1e-3 * std::max(1.0, n.block<2, 2>(0, 0).trace());
  Eigen::Vector4d u = Eigen::Vector4d::Zero();
  if (e.position_determined) {
    u = n.ldlt().solve(b);
  } else {
    u.head<2>() = n.block<2, 2>(0, 0).ldlt().solve(b.head<2>());
  }
  e.yaw_rad = std::atan2(u(1), u(0));
  e.scale = std::hypot(u(0), u(1));
  e.x_m = u(2);
  e.y_m = u(3);
  e.pairs = pairs.size();
  return e;
}

}  // namespace umbmark::scan
