// Motion segmentation (see effects_motion.hpp).
#include "simulation/effects_motion.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "core/errors.hpp"

namespace umbmark::sim {

const char* MotionClassToString(MotionClass c) {
  switch (c) {
    case MotionClass::kStraight: return "straight";
    case MotionClass::kTurn: return "turn";
    case MotionClass::kArc: return "arc";
  }
  return "?";
}

std::string MotionOptions::Check() const {
  if (!(stand_eps_m >= 0.0) || !std::isfinite(stand_eps_m))
    return fmt::format("stand_eps_m = {} must be a finite number >= 0", stand_eps_m);
  if (min_stand_intervals < 1) return fmt::format("min_stand_intervals = {} must be >= 1", min_stand_intervals);
  if (!(straight_max_rad > 0.0)) return fmt::format("straight_max_rad = {} must be > 0", straight_max_rad);
  if (!(turn_max_ratio > 0.0 && turn_max_ratio < 1.0))
    return fmt::format("turn_max_ratio = {} must be in (0, 1)", turn_max_ratio);
  return {};
}

MotionClass ClassifyMotion(double left_m, double right_m, double wheelbase_m, const MotionOptions& options) {
  const double ds = 0.5 * (left_m + right_m);
  const double dw = 0.5 * (right_m - left_m);
  if (std::abs(right_m - left_m) / wheelbase_m <= options.straight_max_rad) return MotionClass::kStraight;
  if (std::abs(ds) <= options.turn_max_ratio * std::abs(dw)) return MotionClass::kTurn;
  return MotionClass::kArc;
}

namespace {

/// Sign of a wheel's travel in interval i (0: still).
int TravelSign(const std::vector<double>& cum, std::size_t i, double eps) {
  const double d = cum[i + 1] - cum[i];
  return d > eps ? 1 : d < -eps ? -1 : 0;
}

/// Intervals between the first two moving intervals of one wheel met when
/// walking from `from` towards `to` (either direction, both included), for
/// the first wheel to move twice (the faster one, as a rule); 0 when
/// neither does. stop(i) ends the walk before interval i.
template <class Stop>
std::size_t TickSpacing(const std::vector<double>& cum_left, const std::vector<double>& cum_right, double eps,
                        std::size_t from, std::size_t to, const Stop& stop) {
  std::size_t seen[2][2] = {{0, 0}, {0, 0}}, found[2] = {0, 0};
  const std::size_t n = from <= to ? to - from : from - to;
  for (std::size_t step = 0; step <= n; ++step) {
    const std::size_t i = from <= to ? from + step : from - step;
    if (stop(i)) break;
    for (int w = 0; w < 2; ++w) {
      if (TravelSign(w == 0 ? cum_left : cum_right, i, eps) == 0) continue;
      seen[w][found[w]++] = i;
      if (found[w] == 2) return seen[w][0] > seen[w][1] ? seen[w][0] - seen[w][1] : seen[w][1] - seen[w][0];
    }
  }
  return 0;
}

/// The still stretch [last + 1, k) after a motion's intervals first..last
/// and the count spacings next to it (TickSpacing; 0: fewer than two
/// counts on that side). After the stretch the walk ends where stop(i)
/// says, or at a still stretch longer than this one (a lone count between
/// two pauses, e.g. a wheel settling by a tick, tells no speed).
struct GapSpacings {
  std::size_t gap = 0, before = 0, after = 0;
};
template <class Stop>
GapSpacings SpacingsAround(const std::vector<double>& cum_left, const std::vector<double>& cum_right, double eps,
                           std::size_t first, std::size_t last, std::size_t k, const Stop& stop) {
  GapSpacings out;
  out.gap = k - (last + 1);
  out.before = TickSpacing(cum_left, cum_right, eps, last, first, [](std::size_t) { return false; });
  std::size_t still = 0;
  out.after = TickSpacing(cum_left, cum_right, eps, k, cum_left.size() - 2, [&](std::size_t i) {
    if (stop(i)) return true;
    const bool moves = TravelSign(cum_left, i, eps) != 0 || TravelSign(cum_right, i, eps) != 0;
    still = moves ? 0 : still + 1;
    return still > out.gap;
  });
  return out;
}

/// Whether a motion (intervals first..last so far) moves on through the
/// still stretch [last + 1, k) of at least min_stand_intervals that ends at
/// moving interval k. A wheel moving at speed v counts a tick every
/// tick / v seconds, so a still stretch no longer than that is what a
/// moving wheel shows between two counts; it is no standstill. At 500
/// ticks/rev and 50 Hz a spot turn from rest (or braking into its end)
/// under an acceleration limit counts in bursts two or three still samples
/// apart, and reading those gaps as standstills put turning into the
/// standstills. The time of one tick there is read from the counts next to
/// the gap: the spacing (in sample intervals) of a wheel's last two counts
/// before it in the motion, or its first two after it (with no longer still
/// stretch between them), the longer of the two, since a motion slows into
/// a gap or speeds up out of it. The motion
/// moves through when no wheel reverses at the gap's end and the gap lasts
/// no more intervals than that spacing. A pause as a campaign commands it
/// (a second, or half of one) lasts many ticks' time even at creep speed:
/// it stays a standstill.
template <class Reverses>
bool MovesThroughGap(const std::vector<double>& cum_left, const std::vector<double>& cum_right,
                     const MotionOptions& options, std::size_t first, std::size_t last, std::size_t k,
                     const Reverses& reverses) {
  if (reverses(k)) return false;
  // After the gap only up to a reversal (the start of another motion).
  const auto [gap, before, after] = SpacingsAround(cum_left, cum_right, options.stand_eps_m, first, last, k, reverses);
  // A lone count on one side of the gap (a motion's last count as it stops,
  // or its first as it starts) gives no spacing there. Under constant
  // deceleration to rest at a count the ticks before it come at times
  // proportional to sqrt(k) (k ticks from the stop): the last spacing is
  // 1 / (sqrt(2) - 1) = 1 + sqrt(2) times the one before; a start from
  // rest is the mirror image (less when the wheel rested inside its tick).
  // In whole sample intervals a spacing s stands for up to s + 1 intervals
  // of time, and a gap g for a spacing of g + 1. Measured on the
  // independent generator's turns at 500 ticks/rev and 50 Hz braking at
  // 0.46 rad/s^2: spacings 2, 2, then 5 to a lone last count, 3 mrad of
  // turning in the gap.
  constexpr double kLastSpacingRatio = 1.0 + std::numbers::sqrt2;
  if (after == 0 && before > 0) return static_cast<double>(gap + 1) <= kLastSpacingRatio * static_cast<double>(before + 1);
  if (before == 0 && after > 0) return static_cast<double>(gap + 1) <= kLastSpacingRatio * static_cast<double>(after + 1);
  return gap <= std::max(before, after);
}

/// Whether the still stretch [last + 1, k) that ended a motion (first..last)
/// is a brief stop: the robot braked to rest and started the next motion
/// at once, as between a leg and a spot turn without a pause. Braking lets
/// a wheel run on after its last count for at most about one count
/// spacing (at constant speed it stops on the count), and starting from
/// rest takes about one spacing of the next motion to its first count; a
/// stretch no longer than the two together is no commanded pause (at 50 Hz
/// and 500 ticks/rev: 3-4 still samples between spacings of 1-2, against
/// 25-50 for a pause of 0.5-1 s). Both spacings come from the counts next
/// to the stretch (SpacingsAround); a side with fewer than two counts gives
/// no spacing and no brief stop.
bool BriefStop(const std::vector<double>& cum_left, const std::vector<double>& cum_right, const MotionOptions& options,
               std::size_t first, std::size_t last, std::size_t k) {
  const auto [gap, before, after] = SpacingsAround(cum_left, cum_right, options.stand_eps_m, first, last, k,
                                                   [](std::size_t) { return false; });
  // In whole intervals a spacing s stands for up to s + 1 intervals of
  // time and the gap g for a spacing of g + 1 (as for a lone count).
  return before > 0 && after > 0 && gap + 1 <= (before + 1) + (after + 1);
}

}  // namespace

// Longer than 80 lines on purpose: one scan over the encoder intervals in
// which a motion's end (a lasting reversal of either wheel, or a still
// stretch it cannot move through) depends on the directions and the last
// moving interval found so far; the tests of a gap and a brief stop are
// helpers above.
std::vector<MotionSegment> SegmentMotions(const std::vector<double>& cum_left, const std::vector<double>& cum_right,
                                          double wheelbase_m, const MotionOptions& options) {
  if (auto e = options.Check(); !e.empty()) throw InvalidOptions("MotionOptions: " + e);
  if (cum_left.size() != cum_right.size())
    throw InvalidOptions("SegmentMotions: cum_left and cum_right differ in length");
  std::vector<MotionSegment> out;
  const std::size_t n = cum_left.size();
  if (n < 2) return out;
  const std::size_t intervals = n - 1;
  auto moving = [&](std::size_t i) {
    return std::abs(cum_left[i + 1] - cum_left[i]) > options.stand_eps_m ||
           std::abs(cum_right[i + 1] - cum_right[i]) > options.stand_eps_m;
  };
  auto sign = [&](const std::vector<double>& cum, std::size_t i) { return TravelSign(cum, i, options.stand_eps_m); };
  std::size_t i = 0;
  bool next_after_brief_stop = false;  // of the motion found next
  while (i < intervals) {
    if (!moving(i)) {
      ++i;
      continue;
    }
    MotionSegment m;
    m.first_interval = i;
    m.after_brief_stop = next_after_brief_stop;
    next_after_brief_stop = false;
    std::size_t last = i;
    std::size_t j = i + 1;
    // Each wheel's direction so far (0 until it moves): a wheel that turns
    // the other way starts the next motion (a leg followed by a turn with no
    // pause, a reversal).
    int dir_l = sign(cum_left, i), dir_r = sign(cum_right, i);
    // A reversal counts when it lasts min_stand_intervals intervals (a
    // wheel jittering by a tick does not end a motion).
    auto reverses = [&](std::size_t k) {
      const int sl = sign(cum_left, k), sr = sign(cum_right, k);
      return (sl != 0 && dir_l != 0 && sl != dir_l) || (sr != 0 && dir_r != 0 && sr != dir_r);
    };
    auto lasting_reversal = [&](std::size_t k) {
      for (std::size_t q = k; q < k + static_cast<std::size_t>(options.min_stand_intervals); ++q)
        if (q >= intervals || !reverses(q)) return false;
      return true;
    };
    while (j < intervals) {
      if (moving(j)) {
        const int sl = sign(cum_left, j), sr = sign(cum_right, j);
        if (lasting_reversal(j)) break;
        if (dir_l == 0) dir_l = sl;
        if (dir_r == 0) dir_r = sr;
        last = j;
        ++j;
        continue;
      }
      // A still stretch: long enough to end the motion?
      std::size_t k = j;
      while (k < intervals && !moving(k)) ++k;
      if (k == intervals) break;
      if (k - j >= static_cast<std::size_t>(options.min_stand_intervals) &&
          !(options.move_through_tick_gaps &&
            MovesThroughGap(cum_left, cum_right, options, m.first_interval, last, k, reverses))) {
        next_after_brief_stop =
            options.move_through_tick_gaps && BriefStop(cum_left, cum_right, options, m.first_interval, last, k);
        break;
      }
      j = k;  // the motion continues through the gap
    }
    m.last_interval = last;
    m.left_m = cum_left[last + 1] - cum_left[m.first_interval];
    m.right_m = cum_right[last + 1] - cum_right[m.first_interval];
    m.cls = ClassifyMotion(m.left_m, m.right_m, wheelbase_m, options);
    if (m.cls == MotionClass::kTurn)
      m.sign = m.right_m - m.left_m >= 0.0 ? 1 : -1;
    else
      m.sign = m.right_m + m.left_m >= 0.0 ? 1 : -1;
    // A brief stop is one between motions in different directions (a leg
    // and a spot turn, a reversal): a wheel that ran one way runs the other
    // after it. A wheel pausing for a sample or two and going on the same
    // way (stiction at a slow start) is no brief stop; that stretch stays a
    // standstill.
    if (m.after_brief_stop && !out.empty()) {
      const MotionSegment& p = out.back();
      const double eps = options.stand_eps_m;
      auto opposite = [eps](double a, double b) { return (a > eps && b < -eps) || (a < -eps && b > eps); };
      m.after_brief_stop = opposite(p.left_m, m.left_m) || opposite(p.right_m, m.right_m);
    }
    out.push_back(m);
    i = last + 1;
  }
  return out;
}

}  // namespace umbmark::sim
