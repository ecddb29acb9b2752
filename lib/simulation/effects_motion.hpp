// Motion segmentation of a run from its cumulative wheel travel: which
// samples are standstill, where each motion starts from standstill, and
// whether a motion is a straight leg, an on-the-spot turn or an arc. The
// effects table speaks of "on-the-spot turns" (turn_scrub) and "starts from
// standstill" (castor_kick); the simulator (when it replays a recorded run)
// and the diagnosis (always) decide both with this one function, so they
// agree on where an effect applies.
//
// Interval i runs from sample i to sample i + 1. An interval is still when
// neither wheel moved more than stand_eps_m. A motion is a maximal run of
// moving intervals in which neither wheel reverses its direction for
// min_stand_intervals intervals or more (a tick of jitter is no reversal);
// still stretches shorter than that inside it belong to it (a slow wheel
// may skip an encoder tick). A longer still stretch ends the motion unless
// the wheels move on through it: no wheel reverses after it and it lasts no
// more intervals than one tick takes at the motion's speed there (a
// wheel's count spacing next to the gap; coarse encoders at high sample
// rates count a slow start or stop in bursts). A lone count next to the gap
// (the last as the motion brakes to rest, or the first as it starts) has
// no spacing of its own: it belongs to the motion when the gap is at most
// 1 + sqrt(2) times the spacing on the other side, what constant
// deceleration gives (in whole intervals, see effects_motion.cpp). A leg
// followed by a spot turn without a pause, or a reversal, are two motions:
// "back to back" (the next starts at the interval after the previous one's
// last), or after a brief stop (MotionSegment::after_brief_stop) when the
// encoders stand for a few samples between. A motion is
//   straight  when its nominal heading change |R - L| / b <= straight_max_rad,
//   turn      when |L + R| / 2 <= turn_max_ratio * |R - L| / 2 (the axle centre
//             barely moves compared with the wheels),
//   arc       otherwise
// with L, R the motion's total nominal wheel travel and b the wheelbase.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace umbmark::sim {

enum class MotionClass { kStraight, kTurn, kArc };
const char* MotionClassToString(MotionClass c);

struct MotionSegment {
  std::size_t first_interval = 0;  ///< first moving interval
  std::size_t last_interval = 0;   ///< last interval of the motion (inclusive)
  MotionClass cls = MotionClass::kStraight;
  /// straight / arc: +1 forward, -1 backward (sign of L + R); turn: +1 ccw, -1 cw.
  int sign = 1;
  double left_m = 0.0, right_m = 0.0;  ///< total nominal travel
  /// The still stretch before this motion (min_stand_intervals or more) is
  /// a brief stop, no pause: it lasts no longer than the count spacing of
  /// the motion before it plus that of this one (braking to rest, starting
  /// again), and a wheel runs the other way than before it, as between a
  /// leg and a spot turn without a commanded pause at coarse encoders. No start from standstill (castor_kick), and the
  /// diagnosis lays no standstill piece there. Only with
  /// move_through_tick_gaps.
  bool after_brief_stop = false;
  /// First sample of the motion (= first_interval) and one past its end
  /// (= last_interval + 1), for convenience.
  std::size_t FirstSample() const { return first_interval; }
  std::size_t EndSample() const { return last_interval + 1; }
};

struct MotionOptions {
  /// Largest per-interval wheel travel [m] counted as "not moving". For
  /// encoder ticks use half a tick. Default 1e-9.
  double stand_eps_m = 1e-9;
  /// Shortest still stretch (intervals) that separates two motions. Default 2.
  int min_stand_intervals = 2;
  /// A longer still stretch is no standstill when the wheels move on
  /// through it at a speed where one tick takes as long (see the file
  /// comment). False: every still stretch of min_stand_intervals ends the
  /// motion (the reading before; kept for comparison). Default true.
  bool move_through_tick_gaps = true;
  /// See the file comment. Defaults 0.1 rad and 0.1.
  double straight_max_rad = 0.1;
  double turn_max_ratio = 0.1;

  std::string Check() const;
};

/// Motions of a run, in order. cum_left / cum_right: cumulative nominal wheel
/// travel per sample [m] (same length). Precondition: wheelbase_m > 0.
std::vector<MotionSegment> SegmentMotions(const std::vector<double>& cum_left, const std::vector<double>& cum_right,
                                          double wheelbase_m, const MotionOptions& options = {});

/// Class of a motion from its total nominal travels (see file comment).
MotionClass ClassifyMotion(double left_m, double right_m, double wheelbase_m, const MotionOptions& options = {});

}  // namespace umbmark::sim
