// The diagnosis' view of a campaign: runs, motions, pieces (see pieces.hpp).
#include "diagnosis/pieces.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "formats/data_file.hpp"
#include "formats/manifest.hpp"
#include "kinematics/diff_drive.hpp"
#include "kinematics/odometry.hpp"
#include "model/commanded_square.hpp"

namespace umbmark::diag {

const char* PieceTypeToString(PieceType t) {
  switch (t) {
    case PieceType::kStraight: return "straight";
    case PieceType::kTurn: return "spot turn";
    case PieceType::kArc: return "arc";
    case PieceType::kStand: return "standstill";
    case PieceType::kReturn: return "return error";
  }
  return "?";
}

std::string PieceOptions::Check() const {
  if (!(max_piece_length_m > 0.0)) return fmt::format("max_piece_length_m = {} must be > 0", max_piece_length_m);
  if (!(max_piece_angle_rad > 0.0)) return fmt::format("max_piece_angle_rad = {} must be > 0", max_piece_angle_rad);
  if (folds < 2) return fmt::format("folds = {} must be >= 2", folds);
  if (!(start_lead_fraction > 0.0))
    return fmt::format("start_lead_fraction = {} must be > 0", start_lead_fraction);
  if (auto e = motion.Check(); !e.empty()) return "motion: " + e;
  return {};
}

namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

double IntervalTravel(const DiagRun& r, std::size_t i) {
  return std::max(std::abs(r.left[i + 1] - r.left[i]), std::abs(r.right[i + 1] - r.right[i]));
}

/// Expected fraction of a tick beyond the count (see DiagRun::q_sd_left)
/// and the remaining quantisation sd, for one wheel of a run with counts.
/// stop_dir / stop_motion: the direction (+1 forward, -1 backward) of the
/// stop the sample rests after and that motion's index (0 / -1 while
/// moving or before the first motion).
void QuantisationPhase(const std::vector<std::int64_t>& ticks, const std::vector<sim::MotionSegment>& motions,
                       double tick_m, std::vector<double>& cum_m, std::vector<double>& sd_m,
                       std::vector<signed char>& stop_dir, std::vector<int>& stop_motion) {
  const std::size_t n = ticks.size();
  cum_m.resize(n);
  sd_m.assign(n, 0.0);
  stop_dir.assign(n, 0);
  stop_motion.assign(n, -1);
  int last_motion = -1;
  std::vector<double> phase(n, 0.5);
  const double unknown = tick_m / std::sqrt(12.0);
  int last_dir = 0;  // direction of the last movement before the current standstill
  std::size_t next = 0;
  for (std::size_t i = 0; i < n; ++i) {
    while (next < motions.size() && motions[next].EndSample() < i) {
      // The motion is over: remember which way this wheel last turned.
      for (std::size_t k = motions[next].EndSample(); k > motions[next].FirstSample(); --k) {
        const std::int64_t d = ticks[k] - ticks[k - 1];
        if (d != 0) {
          last_dir = d > 0 ? 1 : -1;
          last_motion = static_cast<int>(next);
          break;
        }
      }
      ++next;
    }
    bool moving = false;
    if (next < motions.size() && motions[next].FirstSample() < i && i < motions[next].EndSample())
      moving = ticks[motions[next].EndSample()] != ticks[motions[next].FirstSample()] ||
               ticks[i] != ticks[motions[next].FirstSample()];
    if (moving || last_dir == 0) {
      phase[i] = 0.5;
      sd_m[i] = unknown;
    } else {
      // A stop ends a motion at the sample after its last moving interval,
      // so the motion's own end sample is stopped too.
      phase[i] = last_dir > 0 ? 0.0 : 1.0;
      stop_dir[i] = static_cast<signed char>(last_dir);
      stop_motion[i] = last_motion;
    }
    if (!moving && next < motions.size() && i == motions[next].EndSample()) {
      int dir = 0;
      for (std::size_t k = i; k > motions[next].FirstSample(); --k) {
        const std::int64_t d = ticks[k] - ticks[k - 1];
        if (d != 0) {
          dir = d > 0 ? 1 : -1;
          break;
        }
      }
      if (dir != 0) {
        phase[i] = dir > 0 ? 0.0 : 1.0;
        sd_m[i] = 0.0;
        stop_dir[i] = static_cast<signed char>(dir);
        stop_motion[i] = static_cast<int>(next);
      }
    }
    cum_m[i] = (static_cast<double>(ticks[i] - ticks[0]) + phase[i]) * tick_m;
  }
}

/// Records motion m's end as a stop (DiagRun::Stop): its nominal wheel
/// speeds over up to three full intervals before its last one (or over the
/// whole motion when it is that short).
void AddStop(DiagRun& r, const sim::MotionSegment& m) {
  DiagRun::Stop st;
  st.interval = m.last_interval;
  st.cls = static_cast<signed char>(m.cls);
  st.turn_m = std::abs(m.right_m - m.left_m);
  const std::size_t i = m.last_interval;
  st.t_stop = r.t[i] + static_cast<double>(r.window_end[i]) * (r.t[i + 1] - r.t[i]);
  const std::size_t hi = m.last_interval, lo = hi > m.first_interval + 3 ? hi - 3 : m.first_interval;
  if (hi > lo && r.t[hi] > r.t[lo]) {
    st.rate_left = (r.left[hi] - r.left[lo]) / (r.t[hi] - r.t[lo]);
    st.rate_right = (r.right[hi] - r.right[lo]) / (r.t[hi] - r.t[lo]);
  } else if (r.t[m.EndSample()] > r.t[m.FirstSample()]) {
    const double dt = r.t[m.EndSample()] - r.t[m.FirstSample()];
    st.rate_left = m.left_m / dt;
    st.rate_right = m.right_m / dt;
  }
  r.stop_of[m.last_interval] = static_cast<int>(r.stops.size());
  r.stops.push_back(st);
}

/// Interval classes, castor kicks and active windows from the motions.
void AnnotateIntervals(DiagRun& r, int min_stand_intervals) {
  const std::size_t intervals = r.t.empty() ? 0 : r.t.size() - 1;
  r.interval_class.assign(intervals, -1);
  r.kick.assign(intervals, 0);
  r.swivel.assign(intervals, 0);
  r.reversal.assign(intervals, 0);
  r.first_start.assign(intervals, 0);
  r.stop_of.assign(intervals, -1);
  r.coast_of.assign(intervals, -1);
  r.stops.clear();
  r.window_start.assign(intervals, 0.0f);
  r.window_end.assign(intervals, 1.0f);
  for (std::size_t k = 0; k < r.motions.size(); ++k) {
    const sim::MotionSegment& m = r.motions[k];
    for (std::size_t i = m.first_interval; i <= m.last_interval; ++i)
      r.interval_class[i] = static_cast<signed char>(m.cls);
    // castor_kick: only a start from standstill (the run's first motion, or
    // one after a standstill); spot turns excluded. A standstill is what
    // separates motions (effects_motion.hpp): min_stand_intervals still
    // intervals or more. A shorter still stretch between two motions (a
    // turn's last count, then a leg's first count a sample later under
    // acceleration limits) is a junction: the robot did not pause there.
    const bool from_standstill =
        k == 0 || (m.first_interval - r.motions[k - 1].last_interval > static_cast<std::size_t>(min_stand_intervals) &&
                   !m.after_brief_stop);
    if (from_standstill && m.cls != sim::MotionClass::kTurn)
      r.kick[m.first_interval] = static_cast<signed char>(m.sign);
    // castor_swivel: a straight or arc start right after a spot turn.
    if (k > 0 && m.cls != sim::MotionClass::kTurn && r.motions[k - 1].cls == sim::MotionClass::kTurn)
      r.swivel[m.first_interval] = static_cast<signed char>(r.motions[k - 1].sign);
    if (k > 0 && m.cls != sim::MotionClass::kTurn && r.motions[k - 1].cls != sim::MotionClass::kTurn &&
        r.motions[k - 1].sign != m.sign)
      r.reversal[m.first_interval] = 1;
    if (k == 0 && m.cls != sim::MotionClass::kTurn) r.first_start[m.first_interval] = 1;
    if (m.last_interval > m.first_interval) {
      const double t0 = IntervalTravel(r, m.first_interval), t1 = IntervalTravel(r, m.first_interval + 1);
      if (t1 > 0.0) r.window_start[m.first_interval] = static_cast<float>(1.0 - std::min(1.0, t0 / t1));
      const double tl = IntervalTravel(r, m.last_interval), tp = IntervalTravel(r, m.last_interval - 1);
      if (tp > 0.0) r.window_end[m.last_interval] = static_cast<float>(std::min(1.0, tl / tp));
    }
    // stop_slide: the motion ends at a stop (after its active window).
    const bool stops_here =
        k + 1 == r.motions.size() ||
        (r.motions[k + 1].first_interval - m.last_interval > static_cast<std::size_t>(min_stand_intervals) &&
         !r.motions[k + 1].after_brief_stop);
    if (stops_here && !r.endpoint) {
      AddStop(r, m);
      const std::size_t end = k + 1 < r.motions.size() ? r.motions[k + 1].first_interval : intervals;
      for (std::size_t i = m.last_interval + 1; i < end; ++i) r.coast_of[i] = static_cast<int>(r.stops.size()) - 1;
    }
  }
}

/// Junctions of back-to-back motions (see DiagRun::Junction): of the two
/// intervals at the meeting point, the one whose travel is a positive mix of
/// A's and B's directions (taken from their neighbouring intervals) is
/// split; the time of each part follows each motion's speed there.
void FindJunctions(DiagRun& r) {
  const std::size_t intervals = r.interval_class.size();
  r.junction_of.assign(intervals, -1);
  r.junctions.clear();
  auto travel = [&](std::size_t i) { return Eigen::Vector2d(r.left[i + 1] - r.left[i], r.right[i + 1] - r.right[i]); };
  for (std::size_t k = 1; k < r.motions.size(); ++k) {
    const sim::MotionSegment& A = r.motions[k - 1];
    const sim::MotionSegment& B = r.motions[k];
    if (A.last_interval + 1 != B.first_interval) continue;
    // Directions and speeds from the neighbours of the junction (or the
    // motions' totals when they are short).
    const std::size_t ia = A.last_interval > A.first_interval ? A.last_interval - 1 : A.last_interval;
    const std::size_t ib = B.first_interval < B.last_interval ? B.first_interval + 1 : B.first_interval;
    Eigen::Vector2d ua = travel(ia), ub = travel(ib);
    if (ia == A.last_interval) ua = Eigen::Vector2d(A.left_m, A.right_m);
    if (ib == B.first_interval) ub = Eigen::Vector2d(B.left_m, B.right_m);
    const double va = ua.norm() / std::max(r.t[ia + 1] - r.t[ia], 1e-12);
    const double vb = ub.norm() / std::max(r.t[ib + 1] - r.t[ib], 1e-12);
    if (!(ua.norm() > 0.0 && ub.norm() > 0.0 && va > 0.0 && vb > 0.0)) continue;
    ua.normalize();
    ub.normalize();
    Eigen::Matrix2d U;
    U << ua, ub;
    if (std::abs(U.determinant()) < 1e-6) continue;  // same direction: nothing to split
    int best = -1;
    double best_mix = 1e-6;
    Eigen::Vector2d best_ab(0.0, 0.0);
    for (std::size_t i : {A.last_interval, B.first_interval}) {
      const Eigen::Vector2d ab = U.lu().solve(travel(i));
      if (ab[0] < -1e-12 || ab[1] < -1e-12) continue;
      const double mix = std::min(ab[0], ab[1]) / std::max(ab[0] + ab[1], 1e-300);
      if (mix > best_mix) {
        best_mix = mix;
        best = static_cast<int>(i);
        best_ab = ab;
      }
    }
    if (best < 0) continue;
    DiagRun::Junction j;
    j.interval = static_cast<std::size_t>(best);
    j.left_m = best_ab[0] * ua[0];
    j.right_m = best_ab[0] * ua[1];
    const double ta = best_ab[0] / va, tb = best_ab[1] / vb;
    j.time_fraction = ta / (ta + tb);
    j.class_a = static_cast<signed char>(A.cls);
    j.class_b = static_cast<signed char>(B.cls);
    r.window_start[j.interval] = 0.0f;
    r.window_end[j.interval] = 1.0f;
    r.junction_of[j.interval] = static_cast<int>(r.junctions.size());
    r.junctions.push_back(j);
  }
}

}  // namespace

void AnnotateRun(DiagRun& r) {
  AnnotateIntervals(r, r.min_stand_intervals);
  FindJunctions(r);
}

namespace {

/// The sample with ground truth in [lo, hi] nearest to `want`; nullopt when
/// there is none.
std::optional<std::size_t> NearestWithGt(const DiagRun& r, std::size_t want, std::size_t lo, std::size_t hi) {
  if (hi >= r.has_gt.size()) hi = r.has_gt.size() - 1;
  if (lo > hi) return std::nullopt;
  want = std::clamp(want, lo, hi);
  for (std::size_t d = 0;; ++d) {
    bool inside = false;
    if (want >= lo + d) {
      inside = true;
      if (r.has_gt[want - d]) return want - d;
    }
    if (want + d <= hi) {
      inside = true;
      if (r.has_gt[want + d]) return want + d;
    }
    if (!inside) return std::nullopt;
  }
}

struct SubsetTable {
  std::map<std::pair<int, std::string>, int> index;
  std::vector<SubsetInfo>* list;
  int Get(int experiment, const std::string& name) {
    auto [it, inserted] = index.emplace(std::make_pair(experiment, name), static_cast<int>(list->size()));
    if (inserted) list->push_back({experiment, name});
    return it->second;
  }
};

std::string SubsetName(ExperimentKind kind, const DiagRun& run, PieceType type, int sign, bool first) {
  std::string group;
  if (kind == ExperimentKind::kBackAndForth) {
    if (type == PieceType::kStraight || type == PieceType::kArc) group = sign > 0 ? "forward leg" : "backward leg";
  } else {
    group = run.direction;
  }
  std::string what = PieceTypeToString(type);
  if (type == PieceType::kStraight || type == PieceType::kArc) what += first ? " (first piece)" : " (later pieces)";
  return group.empty() ? what : group + ", " + what;
}

/// Whether motion mi, a start from standstill, may have begun before the
/// last sample whose counts read still, i.e. the robot's first motion (and a
/// castor kick, for a straight or arc start) may already show there. The
/// robot starts before its first count. Spot turns too: the rotation before
/// a turn's first count otherwise lands in the standstill before it, as a
/// heading bias with the turn's sign (measured on the independent
/// generator's 500 counts/rev campaigns with acceleration limits).
/// At constant speed (as commanded, no acceleration limit) the start lies
/// inside the first moving interval, a tick's time before the first count.
/// Under acceleration from rest it can lie a good part of a sample earlier:
/// the first of the n counts of the first moving interval (the faster
/// wheel's) comes after the fraction 1 / sqrt(n) of the time since the
/// start (constant acceleration), so the start precedes the sample by up to
/// dt / (sqrt(n) - 1). Ambiguous: the speed still rises after the first
/// moving interval (counts of both wheels in the next two intervals; more
/// than 5 % and two counts of quantisation) and that bound exceeds
/// lead_fraction of dt. tick_*_m: metres per count (0 when the run gives
/// distances, whose resolution is unknown: never ambiguous).
bool StartAmbiguous(const DiagRun& r, std::size_t mi, double tick_left_m, double tick_right_m,
                    double lead_fraction) {
  const sim::MotionSegment& m = r.motions[mi];
  const std::size_t i = m.first_interval;
  // From standstill, as AnnotateIntervals reads it for the castor kick.
  const bool from_standstill =
      mi == 0 || (i - r.motions[mi - 1].last_interval > static_cast<std::size_t>(r.min_stand_intervals) &&
                  !m.after_brief_stop);
  if (!from_standstill || i == 0 || !(tick_left_m > 0.0 && tick_right_m > 0.0)) return false;
  auto counts = [&](std::size_t k) {
    return std::abs(r.left[k + 1] - r.left[k]) / tick_left_m + std::abs(r.right[k + 1] - r.right[k]) / tick_right_m;
  };
  const bool rising = m.last_interval < i + 2 || counts(i + 2) > 1.05 * counts(i + 1) + 2.0;
  const double n = std::max(std::abs(r.left[i + 1] - r.left[i]) / tick_left_m,
                            std::abs(r.right[i + 1] - r.right[i]) / tick_right_m);
  return rising && std::sqrt(n) - 1.0 < 1.0 / lead_fraction;
}

/// The mirror of StartAmbiguous at a motion's end: decelerating into the
/// stop, the robot still moves after its last count (the last sub-tick of
/// the stop), up to dt / (sqrt(n) - 1) past the first sample that reads
/// still (n: the faster wheel's counts in the last moving interval).
/// Ambiguous when the speed still falls into the last moving interval and
/// that bound exceeds lead_fraction of dt; never for distance input.
bool StopAmbiguous(const DiagRun& r, std::size_t mi, double tick_left_m, double tick_right_m, double lead_fraction) {
  const sim::MotionSegment& m = r.motions[mi];
  const std::size_t i = m.last_interval;
  if (!(tick_left_m > 0.0 && tick_right_m > 0.0) || m.EndSample() + 1 >= r.t.size()) return false;
  auto counts = [&](std::size_t k) {
    return std::abs(r.left[k + 1] - r.left[k]) / tick_left_m + std::abs(r.right[k + 1] - r.right[k]) / tick_right_m;
  };
  const bool falling = i < m.first_interval + 2 || counts(i - 2) > 1.05 * counts(i - 1) + 2.0;
  const double n = std::max(std::abs(r.left[i + 1] - r.left[i]) / tick_left_m,
                            std::abs(r.right[i + 1] - r.right[i]) / tick_right_m);
  return falling && std::sqrt(n) - 1.0 < 1.0 / lead_fraction;
}

/// Builds the pieces of one logged run (AddTrajectoryPieces): the
/// standstills between motions and each motion cut into pieces, then which
/// pieces start or end at a standstill, then the standstill averaging.
class TrajectoryPieces {
 public:
  TrajectoryPieces(CampaignData& c, int run_index, ExperimentKind kind, const PieceOptions& o, SubsetTable& subsets,
                   double tick_left_m, double tick_right_m)
      : c_(c),
        r_(c.runs[static_cast<std::size_t>(run_index)]),
        run_index_(run_index),
        kind_(kind),
        o_(o),
        subsets_(subsets),
        tick_left_m_(tick_left_m),
        tick_right_m_(tick_right_m) {}

  void Build() {
    const std::size_t n = r_.t.size();
    g0_ = n;
    g1_ = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (r_.has_gt[i]) {
        g0_ = std::min(g0_, i);
        g1_ = i;
      }
    if (g0_ >= g1_) return;
    first_piece_ = c_.pieces.size();
    cur_ = g0_;
    for (std::size_t mi = 0; mi < r_.motions.size(); ++mi) AddMotion(mi);
    if (g1_ > cur_) Add(cur_, g1_, PieceType::kStand, 0, false);
    MarkStandstillNeighbours();
    if (o_.average_standstills) AverageStandstills();
  }

 private:
  /// One piece from sample a to b (none when b <= a).
  void Add(std::size_t a, std::size_t b, PieceType type, int sign, bool first) {
    if (b <= a) return;
    Piece p;
    p.run = run_index_;
    p.a = p.a_lo = p.a_hi = a;
    p.b = p.b_lo = p.b_hi = b;
    p.type = type;
    p.sign = sign;
    p.motion_first = first;
    double travel = 0.0;
    for (std::size_t i = a; i < b; ++i)
      travel += 0.5 * (std::abs(r_.left[i + 1] - r_.left[i]) + std::abs(r_.right[i + 1] - r_.right[i]));
    p.travel_m = travel;
    if (type == PieceType::kStand && travel > 0.0) {
      // Ground truth missing where a motion starts or ends: the stretch
      // that was meant as standstill holds motion; type it by its travel.
      const double L = r_.left[b] - r_.left[a], R = r_.right[b] - r_.right[a];
      const sim::MotionClass cls = sim::ClassifyMotion(L, R, c_.robot.wheelbase_m, o_.motion);
      p.type = type = cls == sim::MotionClass::kStraight ? PieceType::kStraight
                      : cls == sim::MotionClass::kTurn   ? PieceType::kTurn
                                                         : PieceType::kArc;
      p.sign = sign = cls == sim::MotionClass::kTurn ? (R - L >= 0.0 ? 1 : -1) : (R + L >= 0.0 ? 1 : -1);
      p.motion_first = first = false;
  }
  p.subset = subsets_.Get(r_.experiment, SubsetName(kind_, r_, type, sign, first));
  p.pooled_subset = subsets_.Get(r_.experiment, std::string("all runs, ") + PieceTypeToString(type));
  p.campaign_subset = subsets_.Get(-1, std::string("all experiments, ") + PieceTypeToString(type));
  c_.pieces.push_back(p);
  }

  /// Motion mi's pieces, and the standstill before it.
  void AddMotion(std::size_t mi) {
    const sim::MotionSegment& m = r_.motions[mi];
    // Back to back with a neighbouring motion (no pause between): the
    // interval in which one ends and the next begins holds parts of both, no
    // single constant-curvature step; the two intervals at the junction stay
    // out of the pieces.
    const bool joined_before = mi > 0 && r_.motions[mi - 1].last_interval + 1 == m.first_interval;
    const bool joined_after = mi + 1 < r_.motions.size() && m.last_interval + 1 == r_.motions[mi + 1].first_interval;
    // The castor kick happens at the motion's start (contract), and the
    // robot starts before its first count (tens of ms with acceleration
    // limits and coarse encoders): when the encoders do not locate the
    // start (StartAmbiguous), the last sample that reads still may
    // already show the kick, so the motion's first piece starts one sample
    // earlier and that sample leaves the standstill
    // (PieceOptions::start_before_first_count).
    const bool early = !joined_before && o_.start_before_first_count &&
                       StartAmbiguous(r_, mi, tick_left_m_, tick_right_m_, o_.start_lead_fraction);
    // After a brief stop (effects_motion.hpp) the motion's first piece
    // starts where the one before ended: the still samples between hold
    // the braking and the start, not a standstill.
    const bool brief = m.after_brief_stop && mi > 0 && cur_ <= m.FirstSample();
    const std::size_t s0 = joined_before ? m.FirstSample() + 1
                           : brief       ? cur_
                           : early       ? m.FirstSample() - 1
                                         : m.FirstSample();
    const bool late = !joined_after && o_.start_before_first_count &&
                      StopAmbiguous(r_, mi, tick_left_m_, tick_right_m_, o_.start_lead_fraction);
    const std::size_t s1 = m.EndSample() - (joined_after ? 1 : 0) + (late ? 1 : 0);
    if (s1 <= s0 || s1 <= cur_ || s0 >= g1_) {
      if (joined_after) cur_ = std::max(cur_, std::min(m.EndSample() + 1, g1_));
      return;
  }
  if (joined_before) cur_ = std::max(cur_, std::min(s0, g1_));
  const auto start = s0 <= cur_ ? std::optional<std::size_t>(cur_) : NearestWithGt(r_, s0, cur_, s1 - 1);
  if (!start) return;
  if (*start > cur_) Add(cur_, *start, PieceType::kStand, 0, false);
  const PieceType type = m.cls == sim::MotionClass::kStraight ? PieceType::kStraight
                         : m.cls == sim::MotionClass::kTurn   ? PieceType::kTurn
                                                              : PieceType::kArc;
  const std::vector<std::size_t> cuts = Cuts(m, type, s0, s1);
  std::size_t prev = *start;
  bool first = true;
  for (std::size_t cut : cuts) {
    const auto at = NearestWithGt(r_, cut, prev + 1, std::min(s1, g1_) - 1);
    if (!at) continue;
    Add(prev, *at, type, m.sign, first);
    first = false;
    prev = *at;
  }
  // End of the motion: its first still sample, or the sample before the
  // junction with the next motion (or the nearest with ground truth).
  const auto end = NearestWithGt(r_, std::min(s1, g1_), prev + 1, joined_after ? std::min(s1, g1_) : g1_);
  if (!end) {
    cur_ = joined_after ? std::min(s1 + 2, g1_) : prev;
    return;
  }
  Add(prev, *end, type, m.sign, first);
  cur_ = joined_after ? std::max(*end, std::min(s1 + 2, g1_)) : *end;
  }

  /// Split points of a motion from s0 to s1, by travelled distance (or
  /// heading for turns).
  std::vector<std::size_t> Cuts(const sim::MotionSegment& m, PieceType type, std::size_t s0, std::size_t s1) const {
    int parts = 1;
    if (type == PieceType::kTurn) {
      const double angle = std::abs(m.right_m - m.left_m) / c_.robot.wheelbase_m;
      parts = std::max(1, static_cast<int>(std::ceil(angle / o_.max_piece_angle_rad)));
    } else {
      const double len = 0.5 * (std::abs(m.left_m) + std::abs(m.right_m));
      parts = std::max(1, static_cast<int>(std::ceil(len / o_.max_piece_length_m)));
  }
  std::vector<std::size_t> cuts;
  if (parts > 1) {
    double total = 0.0;
    std::vector<double> cum(s1 - s0 + 1, 0.0);
    for (std::size_t i = s0; i < s1; ++i) {
      total += IntervalTravel(r_, i);
      cum[i - s0 + 1] = total;
    }
    for (int k = 1; k < parts; ++k) {
      const double want = total * k / parts;
      std::size_t j = s0;
      while (j < s1 && cum[j - s0] < want) ++j;
      cuts.push_back(j);
    }
  }
  return cuts;
  }

  void MarkStandstillNeighbours() {
    for (std::size_t j = first_piece_; j < c_.pieces.size(); ++j) {
      Piece& p = c_.pieces[j];
      if (p.type == PieceType::kStand) continue;
      const bool stand_before =
          j == first_piece_ || (c_.pieces[j - 1].type == PieceType::kStand && c_.pieces[j - 1].b == p.a);
      p.starts_from_standstill = p.motion_first && stand_before;
      p.ends_at_standstill =
          j + 1 < c_.pieces.size() && c_.pieces[j + 1].type == PieceType::kStand && c_.pieces[j + 1].a == p.b;
  }
  }

  /// Motions next to a true standstill (no wheel travel) are measured from
  /// / to its mean ground-truth pose.
  void AverageStandstills() {
    for (std::size_t j = first_piece_; j < c_.pieces.size(); ++j) {
      const Piece& st = c_.pieces[j];
      if (st.type != PieceType::kStand || st.travel_m > 0.0) continue;
      int samples = 0;
      for (std::size_t i = st.a; i <= st.b; ++i) samples += r_.has_gt[i] ? 1 : 0;
      if (samples < 2) continue;
      const double w = 1.0 / samples;
      if (j > first_piece_ && c_.pieces[j - 1].b == st.a && c_.pieces[j - 1].type != PieceType::kStand) {
        Piece& before = c_.pieces[j - 1];
        before.b_lo = st.a;
        before.b_hi = st.b;
        before.b_weight = w;
      }
      if (j + 1 < c_.pieces.size() && c_.pieces[j + 1].a == st.b && c_.pieces[j + 1].type != PieceType::kStand) {
        Piece& after = c_.pieces[j + 1];
        after.a_lo = st.a;
        after.a_hi = st.b;
        after.a_weight = w;
      }
  }
  }

  CampaignData& c_;
  const DiagRun& r_;
  int run_index_;
  ExperimentKind kind_;
  const PieceOptions& o_;
  SubsetTable& subsets_;
  double tick_left_m_, tick_right_m_;
  std::size_t g0_ = 0, g1_ = 0, cur_ = 0, first_piece_ = 0;
};

void AddTrajectoryPieces(CampaignData& c, int run_index, ExperimentKind kind, const PieceOptions& o,
                         SubsetTable& subsets, double tick_left_m, double tick_right_m) {
  TrajectoryPieces(c, run_index, kind, o, subsets, tick_left_m, tick_right_m).Build();
}

/// Synthetic commanded square for an endpoint run: still, motion, still, ...
void BuildEndpointRun(DiagRun& r, const ReturnError& e, double side_m, const RobotParams& robot) {
  const auto dir = SquareDirectionFromString(r.direction);
  const auto motions = CommandedSquare(*dir, side_m, robot.wheelbase_m, true);
  double t = 0.0, L = 0.0, R = 0.0;
  auto push = [&]() {
    r.t.push_back(t);
    r.left.push_back(L);
    r.right.push_back(R);
    t += 10.0;
  };
  push();
  for (const auto& m : motions) {
    push();  // two still intervals before each motion
    push();
    L += m.nominal_left_m;
    R += m.nominal_right_m;
  }
  push();
  push();
  push();
  const std::size_t n = r.t.size();
  Pose2 odo;
  for (std::size_t i = 1; i < n; ++i)
    odo = DiffDriveStep(odo, r.left[i] - r.left[i - 1], r.right[i] - r.right[i - 1], robot.wheelbase_m);
  r.gt.assign(n, Pose2{kNan, kNan, kNan});
  r.has_gt.assign(n, false);
  r.gt[0] = Pose2{};
  r.has_gt[0] = true;
  r.gt[n - 1] = Pose2{odo.x + e.ex_m, odo.y + e.ey_m, odo.theta + e.etheta_rad.value_or(0.0)};
  r.has_gt[n - 1] = true;
  r.has_heading = e.etheta_rad.has_value();
}

/// Adds the runs and pieces of one experiment's file to a campaign: the
/// shared bookkeeping (run numbering, subsets, folds) and one function per
/// kind of file.
class CampaignBuilder {
 public:
  CampaignBuilder(CampaignData& c, const Manifest& manifest, const PieceOptions& options)
      : c_(c), manifest_(manifest), options_(options), subsets_{{}, &c.subsets} {}

  void AddExperiment(std::size_t e, const std::variant<EndpointData, TrajectoryData>& file) {
    const Experiment& ex = manifest_.experiments[e];
    ExperimentInfo info;
    info.kind = ex.kind;
    info.file = ex.file;
    info.side_m = ex.side_m;
    info.distance_m = ex.distance_m;
    per_direction_.clear();
    if (const auto* ep = std::get_if<EndpointData>(&file))
      AddEndpointRuns(e, *ep, info);
    else
      AddTrajectoryRuns(e, std::get<TrajectoryData>(file), info);
    c_.experiments.push_back(info);
  }

  bool any_ticks() const { return any_ticks_; }

 private:
  const std::string& FileName(const Experiment& ex) const { return ex.resolved_file.empty() ? ex.file : ex.resolved_file; }

  /// Cross-validation fold of the next run in `direction`: runs of each
  /// direction are dealt to the folds in turn.
  int FoldOf(const std::string& direction) { return per_direction_[direction]++ % options_.folds; }

  /// A run with its place in the experiment and the campaign.
  DiagRun NewRun(std::size_t e, ExperimentInfo& info, const std::string& id, const std::string& direction) {
    DiagRun r;
    r.experiment = static_cast<int>(e);
    r.index_in_experiment = info.runs++;
    r.campaign_index = campaign_index_++;
    r.id = id;
    r.direction = direction;
    return r;
  }

  /// Finds the intervals and junctions of `r` (wheel travel, times, motions
  /// and quantisation set), appends it to the campaign and returns its fold.
  int AddRun(DiagRun&& r, int min_stand_intervals) {
    r.min_stand_intervals = min_stand_intervals;
    r.q_cov_lr.assign(r.t.size(), 0.0);
    if (r.stop_dir_left.empty()) r.stop_dir_left.assign(r.t.size(), 0);
    if (r.stop_dir_right.empty()) r.stop_dir_right.assign(r.t.size(), 0);
    AnnotateRun(r);
    const int fold = FoldOf(r.direction);
    c_.runs.push_back(std::move(r));
    return fold;
  }

  void AddEndpointRuns(std::size_t e, const EndpointData& ep, ExperimentInfo& info) {
    const Experiment& ex = manifest_.experiments[e];
    if (ex.kind != ExperimentKind::kSquare)
      throw InputError(FileName(ex), fmt::format("experiment {} ({}): endpoint data is only usable for squares", e + 1,
                                                 ExperimentKindToString(ex.kind)));
    info.endpoint = true;
    for (const ReturnError& er : ep.runs) {
      if (!SquareDirectionFromString(er.direction))
        throw InputError(FileName(ex), er.line, 0,
                         fmt::format("run {}: direction '{}' must be cw or ccw", er.run, er.direction));
      DiagRun r = NewRun(e, info, er.run, er.direction);
      r.endpoint = true;
      BuildEndpointRun(r, er, ex.side_m, manifest_.robot);
      sim::MotionOptions mo = options_.motion;
      mo.min_stand_intervals = 2;
      r.motions = sim::SegmentMotions(r.left, r.right, manifest_.robot.wheelbase_m, mo);
      r.q_sd_left.assign(r.t.size(), 0.0);
      r.q_sd_right.assign(r.t.size(), 0.0);
      const int fold = AddRun(std::move(r), mo.min_stand_intervals);
      const DiagRun& run = c_.runs.back();
      Piece p;
      p.run = static_cast<int>(c_.runs.size()) - 1;
      p.a = p.a_lo = p.a_hi = 0;
      p.b = p.b_lo = p.b_hi = run.t.size() - 1;
      p.type = PieceType::kReturn;
      p.components = run.has_heading ? 3 : 2;
      p.subset = subsets_.Get(static_cast<int>(e), run.direction + ", return error");
      p.pooled_subset = subsets_.Get(static_cast<int>(e), "all runs, return error");
      p.fold = fold;
      p.travel_m = 4.0 * ex.side_m;
      c_.pieces.push_back(p);
    }
  }

  void AddTrajectoryRuns(std::size_t e, const TrajectoryData& td, ExperimentInfo& info) {
    const Experiment& ex = manifest_.experiments[e];
    const RobotParams& robot = manifest_.robot;
    for (const TrajectoryRun& tr : td.runs) {
      if (tr.size() < 2) continue;
      if (!tr.HasGroundTruth(0) || !tr.HasGroundTruth(tr.size() - 1))
        throw InputError(FileName(ex), tr.lines.empty() ? 0 : tr.lines.front(), 0,
                         fmt::format("run {}: ground truth is needed at its first and last sample", tr.run));
      DiagRun r = NewRun(e, info, tr.run, tr.direction);
      const WheelTravel w = ComputeWheelTravel(tr, robot, robot);
      any_ticks_ = any_ticks_ || tr.has_ticks();
      r.t = tr.t_s;
      r.left = w.left_m;
      r.right = w.right_m;
      r.gt.resize(tr.size());
      r.has_gt.resize(tr.size());
      for (std::size_t i = 0; i < tr.size(); ++i) {
        r.has_gt[i] = tr.HasGroundTruth(i);
        r.gt[i] = r.has_gt[i] ? tr.GroundTruth(i) : Pose2{kNan, kNan, kNan};
      }
      sim::MotionOptions mo = options_.motion;
      if (tr.has_ticks()) mo.stand_eps_m = 0.5 * std::min(robot.MetresPerTickLeft(), robot.MetresPerTickRight());
      r.motions = sim::SegmentMotions(r.left, r.right, robot.wheelbase_m, mo);
      if (tr.has_ticks()) {
        std::vector<int> motion_left, motion_right;
        QuantisationPhase(tr.ticks_left, r.motions, robot.MetresPerTickLeft(), r.left, r.q_sd_left, r.stop_dir_left,
                          motion_left);
        QuantisationPhase(tr.ticks_right, r.motions, robot.MetresPerTickRight(), r.right, r.q_sd_right,
                          r.stop_dir_right, motion_right);
        // A joint stop: both wheels rest after the same motion (stop_model.hpp).
        for (std::size_t i = 0; i < r.t.size(); ++i)
          if (motion_left[i] != motion_right[i]) r.stop_dir_left[i] = r.stop_dir_right[i] = 0;
      } else {
        r.q_sd_left.assign(r.t.size(), 0.0);
        r.q_sd_right.assign(r.t.size(), 0.0);
      }
      const int fold = AddRun(std::move(r), mo.min_stand_intervals);
      const std::size_t before = c_.pieces.size();
      AddTrajectoryPieces(c_, static_cast<int>(c_.runs.size()) - 1, ex.kind, options_, subsets_,
                          tr.has_ticks() ? robot.MetresPerTickLeft() : 0.0,
                          tr.has_ticks() ? robot.MetresPerTickRight() : 0.0);
      for (std::size_t k = before; k < c_.pieces.size(); ++k) c_.pieces[k].fold = fold;
    }
  }

  CampaignData& c_;
  const Manifest& manifest_;
  const PieceOptions& options_;
  SubsetTable subsets_;
  std::map<std::string, int> per_direction_;
  int campaign_index_ = 0;
  bool any_ticks_ = false;
};

/// A pooled subset holding exactly the pieces of one finer subset (one
/// direction only, one experiment only) would repeat its statistics: it is
/// dropped.
void DropRepeatedSubsets(CampaignData& c) {
  auto drop_duplicates = [&](int Piece::*coarse, auto fine_of) {
    std::map<int, std::map<int, int>> members;  // coarse -> finer -> count
    std::map<int, int> size, fine_size;
    for (const Piece& p : c.pieces) {
      fine_size[fine_of(p)] += 1;
      if (p.*coarse < 0) continue;
      members[p.*coarse][fine_of(p)] += 1;
      size[p.*coarse] += 1;
    }
    for (Piece& p : c.pieces) {
      if (p.*coarse < 0) continue;
      const auto& m = members[p.*coarse];
      if (m.size() == 1 && fine_size[m.begin()->first] == size[p.*coarse]) p.*coarse = -1;
    }
  };
  drop_duplicates(&Piece::pooled_subset, [](const Piece& p) { return p.subset; });
  drop_duplicates(&Piece::campaign_subset,
                  [](const Piece& p) { return p.pooled_subset >= 0 ? p.pooled_subset : p.subset; });
}

}  // namespace

CampaignData BuildCampaign(const Manifest& manifest, const std::vector<std::variant<EndpointData, TrajectoryData>>& files,
                           const PieceOptions& options) {
  if (auto e = options.Check(); !e.empty()) throw InvalidOptions("PieceOptions: " + e);
  if (files.size() != manifest.experiments.size())
    throw InvalidOptions("BuildCampaign: one data file per experiment is needed");
  CampaignData c;
  c.path = manifest.path;
  c.robot = manifest.robot;
  c.ground_truth = manifest.ground_truth;
  c.folds = options.folds;
  CampaignBuilder builder(c, manifest, options);
  for (std::size_t e = 0; e < manifest.experiments.size(); ++e) builder.AddExperiment(e, files[e]);
  if (builder.any_ticks()) {
    c.tick_left_m = manifest.robot.MetresPerTickLeft();
    c.tick_right_m = manifest.robot.MetresPerTickRight();
  }
  if (c.pieces.empty()) throw InputError(manifest.path, "no run of the campaign gives a piece to compare with the model");
  DropRepeatedSubsets(c);
  c.files = files;
  return c;
}

CampaignData LoadCampaign(const std::string& manifest_path, const PieceOptions& options) {
  const Manifest m = io::ReadManifest(manifest_path);
  std::vector<std::variant<EndpointData, TrajectoryData>> files;
  for (const auto& e : m.experiments) {
    io::RunFile rf = io::ReadRunFile(e.resolved_file);
    if (auto* t = std::get_if<TrajectoryData>(&rf))
      files.emplace_back(std::move(*t));
    else
      files.emplace_back(std::move(std::get<EndpointData>(rf)));
  }
  return BuildCampaign(m, files, options);
}

}  // namespace umbmark::diag
