// Second-order (heading-squared) covariance correction; see second_order.hpp.
#include "error_models/second_order.hpp"

#include <cmath>

#include "kinematics/diff_drive.hpp"

namespace umbmark {
namespace {

/// One piece: signed midpoint travel along its mean direction, and the wheel
/// travel magnitudes that feed the heading variance.
struct Piece {
  Eigen::Vector2d t;  ///< ds * (cos, sin) of the heading at the piece midpoint
  double abs_left, abs_right;
};

SecondOrderBasis Assemble(const std::vector<Piece>& pieces, double B) {
  SecondOrderBasis out;
  const std::size_t m = pieces.size();
  // Suffix sums U_j = sum_{l > j} t_l.
  std::vector<Eigen::Vector2d> suffix(m + 1, Eigen::Vector2d::Zero());
  for (std::size_t j = m; j-- > 0;) suffix[j] = suffix[j + 1] + pieces[j].t;
  double a_before = 0.0, b_before = 0.0;  // heading variance per unit k^2 at the piece start
  const double inv_b2 = 1.0 / (B * B);
  for (std::size_t j = 0; j < m; ++j) {
    const Piece& p = pieces[j];
    const double a = a_before + 0.5 * p.abs_left * inv_b2;  // at the midpoint
    const double b = b_before + 0.5 * p.abs_right * inv_b2;
    const Eigen::Vector2d& U = suffix[j + 1];
    const Eigen::Matrix2d Wj = p.t * p.t.transpose() + p.t * U.transpose() + U * p.t.transpose();
    out.LL.topLeftCorner<2, 2>() += 0.5 * a * a * Wj;
    out.LR.topLeftCorner<2, 2>() += a * b * Wj;
    out.RR.topLeftCorner<2, 2>() += 0.5 * b * b * Wj;
    out.L0.topLeftCorner<2, 2>() += a * Wj;
    out.R0.topLeftCorner<2, 2>() += b * Wj;
    out.P00.topLeftCorner<2, 2>() += 0.5 * Wj;
    out.mL.head<2>() -= 0.5 * a * p.t;
    out.mR.head<2>() -= 0.5 * b * p.t;
    out.m0.head<2>() -= 0.5 * p.t;
    a_before += p.abs_left * inv_b2;
    b_before += p.abs_right * inv_b2;
  }
  return out;
}

void AddPiece(std::vector<Piece>& pieces, const Pose2& from, double dl, double dr, double B) {
  const double ds = 0.5 * (dl + dr);
  const double mid = from.theta + 0.5 * (dr - dl) / B;
  pieces.push_back({ds * Eigen::Vector2d(std::cos(mid), std::sin(mid)), std::abs(dl), std::abs(dr)});
}

}  // namespace

SecondOrderBasis SecondOrderHeadingBasis(const std::vector<WheelSegment>& path, double wheelbase_m,
                                         int pieces_per_segment) {
  std::vector<Piece> pieces;
  Pose2 pose{};
  const int n = std::max(1, pieces_per_segment);
  for (const WheelSegment& s : path) {
    const double dl = s.left_m / n, dr = s.right_m / n;
    for (int i = 0; i < n; ++i) {
      AddPiece(pieces, pose, dl, dr, wheelbase_m);
      pose = DiffDriveStep(pose, dl, dr, wheelbase_m);
    }
  }
  return Assemble(pieces, wheelbase_m);
}

SecondOrderBasis SecondOrderHeadingBasis(const WheelTravel& travel, double wheelbase_m) {
  std::vector<Piece> pieces;
  Pose2 pose{};
  for (std::size_t i = 1; i < travel.left_m.size(); ++i) {
    const double dl = travel.left_m[i] - travel.left_m[i - 1], dr = travel.right_m[i] - travel.right_m[i - 1];
    AddPiece(pieces, pose, dl, dr, wheelbase_m);
    pose = DiffDriveStep(pose, dl, dr, wheelbase_m);
  }
  return Assemble(pieces, wheelbase_m);
}

}  // namespace umbmark
