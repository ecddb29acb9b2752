#include "planning/motions.hpp"

#include <algorithm>
#include <cmath>

#include "core/angles.hpp"

namespace umbmark::planning {

WheelSegment Motion::Wheels(double wheelbase_m) const {
  switch (kind) {
    case Kind::kLine:
      return {distance_m, distance_m};
    case Kind::kTurn:
      return {-0.5 * wheelbase_m * angle_rad, 0.5 * wheelbase_m * angle_rad};
    case Kind::kArc: {
      // Centre path length, signed by the drive direction (speed < 0: backwards).
      const double s = (speed < 0.0 ? -1.0 : 1.0) * radius_m * std::abs(angle_rad);
      return {s - 0.5 * wheelbase_m * angle_rad, s + 0.5 * wheelbase_m * angle_rad};
    }
    case Kind::kPause:
      break;
  }
  return {0.0, 0.0};
}

double Motion::Duration() const {
  switch (kind) {
    case Kind::kLine:
      return std::abs(distance_m) / std::abs(speed);
    case Kind::kTurn:
      return std::abs(angle_rad) / std::abs(speed);
    case Kind::kArc:
      return radius_m * std::abs(angle_rad) / std::abs(speed);
    case Kind::kPause:
      return duration_s;
  }
  return 0.0;
}

const char* MotionKindToString(Motion::Kind k) {
  switch (k) {
    case Motion::Kind::kLine: return "line";
    case Motion::Kind::kTurn: return "turn";
    case Motion::Kind::kArc: return "arc";
    case Motion::Kind::kPause: return "pause";
  }
  return "?";
}

const char* RunKindToString(RunKind k) {
  switch (k) {
    case RunKind::kSquareCw: return "square_cw";
    case RunKind::kSquareCcw: return "square_ccw";
    case RunKind::kBackAndForth: return "back_and_forth";
    case RunKind::kFreePath: return "free_path";
  }
  return "?";
}

namespace {

Motion Line(double d, const MotionTiming& t) { return {Motion::Kind::kLine, d, 0.0, 0.0, t.speed_m_s, 0.0}; }
Motion Turn(double a, const MotionTiming& t) { return {Motion::Kind::kTurn, 0.0, a, 0.0, t.turn_rate_rad_s, 0.0}; }
Motion Pause(double s) { return {Motion::Kind::kPause, 0.0, 0.0, 0.0, 0.0, s}; }

}  // namespace

std::vector<Motion> MotionsOfPath(const std::vector<PathSegment>& path, double wheelbase_m, const MotionTiming& timing) {
  std::vector<Motion> out;
  for (const WheelSegment& w : ToWheelSegments(path, wheelbase_m)) {
    const double s = 0.5 * (w.left_m + w.right_m), a = (w.right_m - w.left_m) / wheelbase_m;
    if (std::abs(a) < 1e-12) {
      out.push_back(Line(s, timing));
    } else if (std::abs(s) < 1e-12) {
      out.push_back(Turn(a, timing));
    } else {
      out.push_back({Motion::Kind::kArc, 0.0, a, std::abs(s / a), s < 0.0 ? -timing.speed_m_s : timing.speed_m_s, 0.0});
    }
  }
  return out;
}

std::vector<Motion> RunMotions(RunKind kind, double size, const std::vector<PathSegment>& spec, double wheelbase_m,
                               const MotionTiming& timing) {
  std::vector<Motion> body;
  switch (kind) {
    case RunKind::kSquareCw:
    case RunKind::kSquareCcw:
      for (int leg = 0; leg < 4; ++leg) {
        body.push_back(Line(size, timing));
        body.push_back(Turn(kind == RunKind::kSquareCw ? -0.5 * kPi : 0.5 * kPi, timing));
      }
      break;
    case RunKind::kBackAndForth:
      body = {Line(size, timing), Line(-size, timing)};
      break;
    case RunKind::kFreePath:
      body = MotionsOfPath(spec, wheelbase_m, timing);
      break;
  }
  std::vector<Motion> out{Pause(timing.EndPause())};
  for (std::size_t i = 0; i < body.size(); ++i) {
    out.push_back(body[i]);
    out.push_back(Pause(i + 1 == body.size() ? timing.EndPause() : timing.pause_s));
  }
  std::erase_if(out, [](const Motion& m) { return m.kind == Motion::Kind::kPause && !(m.duration_s > 0.0); });
  return out;
}

double MotionsDuration(const std::vector<Motion>& motions) {
  double t = 0.0;
  for (const Motion& m : motions) t += m.Duration();
  return t;
}

WheelTravel SampleMotions(const std::vector<Motion>& motions, double wheelbase_m, double rate_hz) {
  // Motion boundaries: start time and cumulative travel at each.
  std::vector<double> t0{0.0}, l0{0.0}, r0{0.0};
  for (const Motion& m : motions) {
    const WheelSegment w = m.Wheels(wheelbase_m);
    t0.push_back(t0.back() + m.Duration());
    l0.push_back(l0.back() + w.left_m);
    r0.push_back(r0.back() + w.right_m);
  }
  const double end = t0.back();
  WheelTravel out;
  const auto samples = static_cast<std::size_t>(std::floor(end * rate_hz + 1e-9)) + 1;
  out.left_m.reserve(samples + 1);
  out.right_m.reserve(samples + 1);
  std::size_t seg = 0;
  auto at = [&](double t) {
    while (seg + 1 < t0.size() - 1 && t >= t0[seg + 1]) ++seg;
    const double len = t0[seg + 1] - t0[seg];
    const double u = len > 0.0 ? std::clamp((t - t0[seg]) / len, 0.0, 1.0) : 1.0;
    out.left_m.push_back(l0[seg] + u * (l0[seg + 1] - l0[seg]));
    out.right_m.push_back(r0[seg] + u * (r0[seg + 1] - r0[seg]));
  };
  if (motions.empty()) {
    out.left_m = {0.0};
    out.right_m = {0.0};
    return out;
  }
  for (std::size_t i = 0; i < samples; ++i) at(static_cast<double>(i) / rate_hz);
  if (static_cast<double>(samples - 1) / rate_hz < end - 1e-9) at(end);
  return out;
}

}  // namespace umbmark::planning
