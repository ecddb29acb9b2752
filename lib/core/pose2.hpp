// Planar pose (x, y, theta) and SE(2) helpers. Frame convention (contract):
// x forward, y left, theta counter-clockwise positive.
//
//        y ^
//          |   theta
//          |  /
//          | /
//          +------> x      every run starts at (0, 0, 0) in its own frame
#pragma once

#include <cmath>

#include "core/angles.hpp"

namespace umbmark {

template <typename T>
struct Pose2T {
  T x{0}, y{0}, theta{0};
};
using Pose2 = Pose2T<double>;

/// a_T_c = a_T_b * b_T_c (composition of rigid motions).
template <typename T>
Pose2T<T> Compose(const Pose2T<T>& a_T_b, const Pose2T<T>& b_T_c) {
  using std::cos;
  using std::sin;
  const T c = cos(a_T_b.theta), s = sin(a_T_b.theta);
  return {a_T_b.x + c * b_T_c.x - s * b_T_c.y, a_T_b.y + s * b_T_c.x + c * b_T_c.y, a_T_b.theta + b_T_c.theta};
}

/// b_T_a = inverse(a_T_b).
template <typename T>
Pose2T<T> Inverse(const Pose2T<T>& a_T_b) {
  using std::cos;
  using std::sin;
  const T c = cos(a_T_b.theta), s = sin(a_T_b.theta);
  return {-c * a_T_b.x - s * a_T_b.y, s * a_T_b.x - c * a_T_b.y, -a_T_b.theta};
}

/// Expresses world_T_p in the frame of world_T_origin: origin_T_p.
/// Used to re-express ground truth in the frame of a run's first sample.
inline Pose2 RelativeTo(const Pose2& world_T_origin, const Pose2& world_T_p) {
  return Compose(Inverse(world_T_origin), world_T_p);
}

}  // namespace umbmark
