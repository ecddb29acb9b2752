// Wheel-travel sanity for `import rosbag2` (see wheel_checks.hpp).
#include "import/wheel_checks.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/angles.hpp"
#include "core/errors.hpp"

namespace umbmark::io::rosbag2 {

namespace {

constexpr double kMinJumpRad = 1.0;     // a step below this is never called a jump
constexpr double kMinJumpM = 0.05;      // (odometry travel)
constexpr double kJumpFactor = 8.0;     // ... nor one below 8x the wheel's 95th-percentile speed
constexpr double kResetNearZero = 0.2;  // a reset lands within this of 0 (plus a few steps)
constexpr double kStillM = 1e-6;        // as the importer's standstill threshold

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const auto at = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(at), v.end());
  return v[at];
}

double Seconds(std::int64_t ns) { return static_cast<double>(ns) * 1e-9; }

// One joint's positions with their stamps: unwrap, then resets and jumps.
class JointSeries {
 public:
  JointSeries(std::vector<WheelSample>& s, bool left, const WheelContext& c)
      : s_(s),
        left_(left),
        joint_(c.odometry ? fmt::format("{} wheel", left ? "left" : "right")
                          : fmt::format("joint {}", left ? c.left_joint : c.right_joint)),
        c_(c) {}
  double& P(std::size_t k) { return left_ ? s_[k].left : s_[k].right; }

  void Unwrap(std::vector<std::string>& warnings) {
    // Wrapped: every position within one revolution ((-pi, pi] or
    // [0, 2 pi)), and steps of more than half a revolution.
    double lo = P(0), hi = P(0);
    std::size_t wraps = 0;
    for (std::size_t k = 0; k < s_.size(); ++k) {
      lo = std::min(lo, P(k));
      hi = std::max(hi, P(k));
      if (k > 0 && std::abs(P(k) - P(k - 1)) > kPi) ++wraps;
    }
    if (wraps == 0 || hi - lo > 2.0 * kPi + 1e-9) return;
    double prev_raw = P(0), max_step = 0.0;
    for (std::size_t k = 1; k < s_.size(); ++k) {
      const double raw = P(k);
      const double step = WrapAngle(raw - prev_raw);
      max_step = std::max(max_step, std::abs(step));
      P(k) = P(k - 1) + step;
      prev_raw = raw;
    }
    warnings.push_back(fmt::format(
        "{}: topic {}, {}: positions are wrapped into one revolution ({} wrap(s)); unwrapped, which is exact while the "
        "wheel turns less than half a revolution between messages (at most {:.3f} rad here)",
        c_.file, c_.topic, joint_, wraps, max_step));
  }

  // Resets are stitched (the wheel assumed to keep the speed of the steps
  // around it); any other jump is refused. JointState: a reset lands near
  // 0 rad; Odometry (travel in metres): where the pose returns to the
  // origin (`at_origin`). One pass, the stitching offset carried along.
  void Jumps(std::vector<std::string>& warnings, const std::vector<bool>* at_origin = nullptr) {
    const double min_jump = at_origin ? kMinJumpM : kMinJumpRad;
    const char* unit = at_origin ? "m" : "rad";
    std::vector<double> speeds;
    for (std::size_t k = 1; k < s_.size(); ++k) {
      const double dt = Seconds(s_[k].t_ns - s_[k - 1].t_ns);
      const double v = std::abs(P(k) - P(k - 1)) / dt;
      if (dt > 0.0 && v > 0.0) speeds.push_back(v);
    }
    const double typical = Quantile(speeds, 0.95);
    std::size_t resets = 0, first_reset = 0;
    double from = 0.0, to = 0.0, offset = 0.0;
    double raw_prev = P(0), raw_prev2 = P(0);
    for (std::size_t k = 1; k < s_.size(); ++k) {
      const double raw = P(k);
      const double dt = Seconds(s_[k].t_ns - s_[k - 1].t_ns);
      const double step = raw - raw_prev;
      if (std::abs(step) > std::max(min_jump, kJumpFactor * typical * dt)) {
        const bool reset = at_origin ? (*at_origin)[k] && !(*at_origin)[k - 1]
                                     : std::abs(raw) <= kResetNearZero + 3.0 * typical * dt &&
                                           std::abs(raw_prev) > 2.0 * std::abs(raw);
        if (!reset) {
          throw InputError(c_.file, fmt::format(
              "topic {}, {}: {} jumps by {:.4g} {} ({:.4g} -> {:.4g} {}) in {:.3f} s at stamp {} (message {}), {:.0f}x "
              "faster than the wheel turns elsewhere ({:.3g} {}/s); not a wrap nor a reset to 0, so it is not repaired: "
              "check the encoder or the driver",
              c_.topic, joint_, at_origin ? "its travel" : "position", step, unit, raw_prev, raw, unit, dt,
              StampText(s_[k].t_ns), s_[k].msg, typical > 0.0 ? std::abs(step) / dt / typical : 0.0, typical, unit));
        }
        if (resets++ == 0) {
          first_reset = k;
          from = raw_prev;
          to = raw;
        }
        // The step over the reset: the mean speed of the steps around it.
        double sum = 0.0;
        int n = 0;
        if (k >= 2) {
          const double d = Seconds(s_[k - 1].t_ns - s_[k - 2].t_ns);
          if (d > 0.0) sum += (raw_prev - raw_prev2) / d, ++n;
        }
        if (k + 1 < s_.size()) {
          const double d = Seconds(s_[k + 1].t_ns - s_[k].t_ns);
          if (d > 0.0) sum += (P(k + 1) - raw) / d, ++n;
        }
        offset += raw_prev + (n > 0 ? sum / n * dt : 0.0) - raw;
      }
      raw_prev2 = raw_prev;
      raw_prev = raw;
      P(k) = raw + offset;
    }
    if (resets > 0) {
      warnings.push_back(fmt::format(
          "{}: topic {}, {}: {} {} time(s) (first at stamp {}, message {}: {:.4g} -> {:.4g} {}; a controller "
          "restart?); stitched, assuming the wheel kept the speed of the messages around each reset",
          c_.file, c_.topic, joint_, at_origin ? "the odometry pose resets to the origin" : "position resets to 0", resets,
          StampText(s_[first_reset].t_ns), s_[first_reset].msg, from, to, unit));
    }
  }

 private:
  std::vector<WheelSample>& s_;
  bool left_;
  std::string joint_;
  const WheelContext& c_;
};

}  // namespace

void SanitizeJointPositions(std::vector<WheelSample>& s, const WheelContext& c, std::vector<std::string>& warnings) {
  if (s.size() < 2) return;
  bool identical = true, moves = false;
  for (std::size_t k = 0; k < s.size(); ++k) {
    identical = identical && s[k].left == s[k].right;
    moves = moves || (k > 0 && s[k].left != s[k - 1].left);
  }
  if (identical && moves) {
    throw InputError(c.file, fmt::format(
        "topic {}: joints {} and {} report the same position in all {} messages: one encoder published twice, or "
        "--left-joint and --right-joint naming the same wheel; name the two wheel joints (see --list)",
        c.topic, c.left_joint, c.right_joint, s.size()));
  }
  for (bool left : {true, false}) {
    JointSeries j(s, left, c);
    j.Unwrap(warnings);
    j.Jumps(warnings);
  }
}

void SanitizeOdometryTravel(std::vector<WheelSample>& s, const std::vector<bool>& at_origin, const WheelContext& c,
                            std::vector<std::string>& warnings) {
  if (s.size() < 2 || at_origin.size() != s.size()) return;
  for (bool left : {true, false}) JointSeries(s, left, c).Jumps(warnings, &at_origin);
}

void CheckStuckWheel(const std::vector<WheelSample>& s, const WheelContext& c) {
  double path_l = 0.0, path_r = 0.0;
  for (std::size_t k = 1; k < s.size(); ++k) {
    path_l += std::abs(s[k].left - s[k - 1].left);
    path_r += std::abs(s[k].right - s[k - 1].right);
  }
  const double most = std::max(path_l, path_r), least = std::min(path_l, path_r);
  if (most > 0.5 && least < 0.02 * most) {
    const bool left_stuck = path_l < path_r;
    throw InputError(c.file, fmt::format(
        "topic {}: joint {} travels {:.4g} m in all while joint {} travels {:.4g} m: a stuck or unplugged encoder, or "
        "the wrong joint (name the wheel with --{}-joint; --list shows the joints)",
        c.topic, left_stuck ? c.left_joint : c.right_joint, least, left_stuck ? c.right_joint : c.left_joint, most,
        left_stuck ? "left" : "right"));
  }
}

std::vector<WheelGap> FindGaps(const std::vector<WheelSample>& s) {
  std::vector<WheelGap> gaps;
  if (s.size() < 3) return gaps;
  std::vector<double> dts;
  for (std::size_t k = 1; k < s.size(); ++k) dts.push_back(Seconds(s[k].t_ns - s[k - 1].t_ns));
  const double typical = Quantile(dts, 0.5);
  const double limit = std::max(1.0, 10.0 * typical);
  for (std::size_t k = 1; k < s.size(); ++k) {
    const double dt = dts[k - 1];
    const double travel = std::max(std::abs(s[k].left - s[k - 1].left), std::abs(s[k].right - s[k - 1].right));
    if (dt > limit && travel >= kStillM) gaps.push_back({k, dt, typical, travel});
  }
  return gaps;
}

}  // namespace umbmark::io::rosbag2
