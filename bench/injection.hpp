// Injection of the contract's effects into REAL recordings (issue 28): the
// encoders stay exactly as recorded, the ground truth changes as the
// physical robot's path would have changed had the effect been there, and
// the real background (the robot's own errors, the motion capture's noise,
// its clock) stays in.  Written from the contract's effect definitions
// (docs/formats.md, "Effects") with NONE of lib/simulation or lib/model:
// the bench keeps its own re-implementation on purpose, so that the
// diagnosis is not checked against its own reading of the definitions.
// Header-only, so that tests/test_injection_recovery.cpp uses the same code
// as the bench tool bench/inject_recordings.cpp.
//
// How (docs/diagnosis.md, "Injection-recovery on real recordings"):
//   * Effects on the true motion.  Per sample interval k the recorded wheel
//     travel (ticks x pi D / ticks_per_rev, nominal geometry) moves the
//     robot by m0_k (exact arc); with the effect the true wheels would move
//     it by m1_k (scaled, bumped, ... travel; a heading jump J_k at a start
//     or a stop).  The recorded ground-truth increment D_k = T_{k-1}^-1 T_k
//     is the ideal motion times a residual, D_k = m0_k e_k (the real robot's
//     own errors and the capture noise); the injected one keeps the
//     residual: D'_k = J_k m1_k m0_k^-1 D_k, and T'_k = T'_{k-1} D'_k.
//   * Effects on the measurement act on the ground truth directly:
//     gt_offset reports T' (dx, dy, 0); a clock offset tau shows at stamp t
//     the pose at t - tau, moved along the recorded wheels' own motion from
//     t to t - tau (ticks interpolated linearly in time; still before the
//     first and after the last sample), T''(t) = T'(t) O(t)^-1 O(t - tau),
//     so the capture noise is kept, not interpolated away.
//   * Motions and standstills come from the encoders alone: a standstill is
//     at least `min_still_s` with no count on either wheel; a motion between
//     two standstills in which neither wheel travels `min_travel_m` is a
//     nudge and belongs to the standstill, and so do the creeps that lead
//     into or trail a motion (its stretches between still samples, shorter
//     than min_still_s, in which neither wheel travels that far: a wheel
//     counting once every few samples is not yet moving the robot, or its
//     castor); a motion is a spot turn when
//     |s_L + s_R| <= turn_ratio |s_R - s_L| over it, else a leg or arc,
//     forward or backward by the sign of s_L + s_R.  A run starts from
//     standstill (the robot is at rest before it), so a run that never
//     stands still starts from standstill once.
//   * The castor's starts (castor_kick, castor_swivel) follow the contract's
//     words literally: a start from standstill is any start after the
//     encoders read still for min_still_s, so there nudges and creeps are
//     motions of their own (min_travel_m does not apply).  A one-wheel creep
//     of a millimetre that ends 0.1 s before a leg is a forward start from
//     standstill, and so is the leg (issue 28: with the nudge rule session
//     s1's squares got 29 kicks where the encoders show 54 starts from
//     standstill, the diagnosis' model marks 46, and a 10 mrad kick came
//     back as 2.3 mrad).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace umbmark_bench {

/// A planar pose or rigid motion: x, y [m], heading th [rad].
struct Pose2 {
  double x = 0.0, y = 0.0, th = 0.0;
};

/// a_T_c = a_T_b * b_T_c.
inline Pose2 Compose(const Pose2& a, const Pose2& b) {
  const double c = std::cos(a.th), s = std::sin(a.th);
  return {a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y, a.th + b.th};
}

inline Pose2 Inverse(const Pose2& a) {
  const double c = std::cos(a.th), s = std::sin(a.th);
  return {-c * a.x - s * a.y, s * a.x - c * a.y, -a.th};
}

/// The exact motion of a differential drive whose wheels travel sL, sR [m]
/// on a circular arc (wheelbase b [m]).
inline Pose2 Arc(double sL, double sR, double b) {
  const double ds = 0.5 * (sL + sR), dth = (sR - sL) / b;
  const double chord = std::abs(dth) < 1e-9 ? ds : ds * std::sin(0.5 * dth) / (0.5 * dth);
  return {chord * std::cos(0.5 * dth), chord * std::sin(0.5 * dth), dth};
}

/// One contract effect with its parameters (contract names).
struct InjectEffect {
  std::string name;
  std::map<std::string, double> params;
  double P(const std::string& key) const {
    const auto it = params.find(key);
    return it == params.end() ? 0.0 : it->second;
  }
};

/// Parses NAME:k=v,k=v (the `simulate --effect` syntax).
inline InjectEffect ParseEffect(const std::string& text) {
  InjectEffect e;
  const auto colon = text.find(':');
  e.name = text.substr(0, colon);
  std::size_t p = colon == std::string::npos ? text.size() : colon + 1;
  while (p < text.size()) {
    const auto comma = text.find(',', p), eq = text.find('=', p);
    const auto end = comma == std::string::npos ? text.size() : comma;
    if (eq == std::string::npos || eq > end) throw std::invalid_argument("effect '" + text + "': expected k=v");
    e.params[text.substr(p, eq - p)] = std::stod(text.substr(eq + 1, end - eq - 1));
    p = end + 1;
  }
  return e;
}

struct InjectOptions {
  double wheelbase_m = 0.2;          ///< nominal wheelbase (the manifest's)
  double diameter_left_m = 0.084;    ///< nominal wheel diameters (the manifest's)
  double diameter_right_m = 0.084;
  double ticks_per_rev = 2796.8;     ///< used when the CSV has ticks
  std::vector<InjectEffect> effects;
  std::uint64_t seed = 1;            ///< every random draw (bumps, standstills, clocks, swivel signs)
  double min_still_s = 0.1;          ///< a standstill: no count on either wheel for at least this long [s]
  double min_travel_m = 0.002;       ///< a motion in which neither wheel travels this far is a nudge [m] (not for the castor's starts)
  double turn_ratio = 0.25;          ///< spot turn when |sL + sR| <= turn_ratio |sR - sL| over the motion
  double stop_window_s = 0.1;        ///< stop_slide: the speed at a stop is the mean over the motion's last window [s]
  int first_run_index = 0;           ///< parameter_drift: index of the file's first run in the campaign
};

/// What an injection did to one file (for the report).
struct InjectSummary {
  int runs = 0, motions = 0, spot_turns = 0, starts_kicked = 0, standstills = 0, bumps = 0;
  double max_position_change_m = 0.0, max_heading_change_rad = 0.0;  ///< largest |T' - T| over the samples
  double mean_stop_speed_mps = 0.0, mean_stop_rate_radps = 0.0;      ///< at the stops after legs / spot turns
  std::vector<double> run_taus_s;                                    ///< run_time_offset: tau_i drawn
};

/// One motion between two standstills (sample intervals first..last,
/// interval k goes from sample k-1 to sample k).
struct Motion {
  int first = 0, last = 0;
  bool turn = false;
  int dir = 1;           ///< legs and arcs: +1 forward, -1 backward
  int turn_sign = 0;     ///< spot turns: +1 ccw, -1 cw
  double stop_speed = 0.0, stop_rate = 0.0;  ///< |v| [m/s], |w| [rad/s] over the last stop_window_s
};

/// The recorded samples of one run.
struct RecordedRun {
  std::vector<double> t, wl, wr;   ///< time [s], cumulative wheel travel [m]
  std::vector<Pose2> gt;           ///< ground truth
  std::vector<bool> has_gt;
};

/// Motions of a run from its encoders alone (see the file comment).
inline std::vector<Motion> SegmentMotions(const RecordedRun& r, const InjectOptions& o) {
  const int n = static_cast<int>(r.t.size());
  std::vector<std::array<int, 2>> raw;   // moving stretches, still gaps shorter than min_still_s inside
  for (int k = 1; k < n;) {
    if (r.wl[k] == r.wl[k - 1] && r.wr[k] == r.wr[k - 1]) {
      ++k;
      continue;
    }
    int last = k;
    int j = k + 1;
    while (j < n) {
      if (r.wl[j] != r.wl[j - 1] || r.wr[j] != r.wr[j - 1]) {
        last = j++;
        continue;
      }
      int e = j;  // still stretch j..e-1
      while (e < n && r.wl[e] == r.wl[e - 1] && r.wr[e] == r.wr[e - 1]) ++e;
      if (e >= n || r.t[e - 1] - r.t[j - 1] >= o.min_still_s) break;
      j = e;
    }
    raw.push_back({k, last});
    k = last + 1;
  }
  std::vector<Motion> out;
  const auto moved = [&](int k) { return r.wl[k] != r.wl[k - 1] || r.wr[k] != r.wr[k - 1]; };
  for (const auto& [a0, b0] : raw) {
    // Leading and trailing creeps (stretches between still samples in which
    // neither wheel travels min_travel_m) belong to the standstill: the
    // motion is from the first to the last stretch that moves that far.
    int a = -1, b = -1;
    for (int k = a0; k <= b0;) {
      int e = k;
      while (e + 1 <= b0 && moved(e + 1)) ++e;
      double ex = 0.0;
      for (int i = k; i <= e; ++i)
        ex = std::max({ex, std::abs(r.wl[i] - r.wl[k - 1]), std::abs(r.wr[i] - r.wr[k - 1])});
      if (ex >= o.min_travel_m) {
        if (a < 0) a = k;
        b = e;
      }
      for (k = e + 1; k <= b0 && !moved(k);) ++k;
    }
    if (a < 0) continue;  // a nudge: part of the standstill
    const double sL = r.wl[b] - r.wl[a - 1], sR = r.wr[b] - r.wr[a - 1];
    Motion m;
    m.first = a;
    m.last = b;
    m.turn = std::abs(sL + sR) <= o.turn_ratio * std::abs(sR - sL);
    m.dir = sL + sR >= 0.0 ? 1 : -1;
    m.turn_sign = sR - sL >= 0.0 ? 1 : -1;
    int w = b;
    while (w > a && r.t[b] - r.t[w - 1] < o.stop_window_s) --w;
    const double dt = std::max(r.t[b] - r.t[w - 1], 1e-9);
    const double dL = r.wl[b] - r.wl[w - 1], dR = r.wr[b] - r.wr[w - 1];
    m.stop_speed = std::abs(0.5 * (dL + dR)) / dt;
    m.stop_rate = std::abs((dR - dL) / o.wheelbase_m) / dt;
    out.push_back(m);
  }
  return out;
}

/// Per interval: the true wheels' travel factor and addition, the heading
/// scale of spot turns and a jump before the interval's motion.
struct IntervalChange {
  double fL = 1.0, fR = 1.0, aL = 0.0, aR = 0.0, turn_scale = 1.0;
  Pose2 jump;
};

/// Random streams of one run: one per effect, so that an effect's draws do
/// not depend on which other effects are injected with it.
struct Streams {
  explicit Streams(std::uint64_t seed)
      : bump(seed ^ 0x1B873593ULL), still(seed ^ 0xCC9E2D51ULL), floor(seed ^ 0x85EBCA6BULL),
        clock(seed ^ 0xC2B2AE35ULL), swivel(seed ^ 0x27D4EB2FULL) {}
  std::mt19937_64 bump, still, floor, clock, swivel;
};

/// The wheel effects (scale, asymmetry, drift, bumps, turn scrub) on each interval.
inline void WheelChanges(const RecordedRun& r, const std::vector<Motion>& motions, const InjectEffect& e,
                         int run_index, Streams& g, std::vector<IntervalChange>& ch, InjectSummary& sum) {
  const int n = static_cast<int>(r.t.size());
  if (e.name == "scale_error") {
    for (auto& c : ch) c.fL = c.fR = c.fL * (1.0 + e.P("s"));
  } else if (e.name == "direction_asymmetry") {
    for (int k = 1; k < n; ++k) {
      if (r.wl[k] < r.wl[k - 1]) ch[k].fL *= 1.0 + e.P("a");
      if (r.wr[k] < r.wr[k - 1]) ch[k].fR *= 1.0 + e.P("a");
    }
  } else if (e.name == "parameter_drift") {
    for (auto& c : ch) c.fR *= 1.0 + e.P("r") * run_index;
  } else if (e.name == "turn_scrub") {
    for (const Motion& m : motions)
      if (m.turn)
        for (int k = m.first; k <= m.last; ++k) ch[k].turn_scale *= 1.0 - e.P("k");
  } else if (e.name == "bump_outliers") {
    const double rate = e.P("rate"), sigma = e.P("sigma");
    if (!(rate > 0.0 && sigma > 0.0)) return;
    std::exponential_distribution<double> gap(rate);
    std::normal_distribution<double> bump(0.0, sigma);
    std::array<double, 2> next{gap(g.bump), gap(g.bump)};
    for (int k = 1; k < n; ++k) {
      const std::array<double, 2> s{std::abs(r.wl[k] - r.wl[k - 1]), std::abs(r.wr[k] - r.wr[k - 1])};
      for (int w = 0; w < 2; ++w)
        for (next[w] -= s[w]; next[w] <= 0.0; next[w] += gap(g.bump)) {
          (w == 0 ? ch[k].aL : ch[k].aR) += bump(g.bump);
          ++sum.bumps;
        }
    }
  }
}

/// The start and stop effects (castor kick and swivel, standstill motion,
/// noise floor, stop slide): jumps at a motion's first interval or at the
/// first still interval after it, and wheel travel added at its ends.
inline void StartStopChanges(const RecordedRun& r, const std::vector<Motion>& motions, const InjectEffect& e,
                             Streams& g, std::vector<IntervalChange>& ch, InjectSummary& sum) {
  const int n = static_cast<int>(r.t.size());
  std::normal_distribution<double> n01(0.0, 1.0);
  int last_turn = 0, last_dir = 0;  // castor_swivel: the spot turn since the last leg, that leg's direction
  for (const Motion& m : motions) {
    Pose2& start = ch[m.first].jump;
    if (e.name == "castor_kick" && !m.turn) {
      start = Compose(start, {0.0, 0.0, m.dir * e.P("kappa")});
      ++sum.starts_kicked;
    } else if (e.name == "castor_swivel") {
      if (m.turn) {
        last_turn = m.turn_sign;
      } else {
        double kick = 0.0;
        if (last_turn != 0) kick = last_turn * e.P("kappa");
        else if (last_dir != 0 && m.dir != last_dir)
          kick = (std::uniform_real_distribution<double>(0.0, 1.0)(g.swivel) < 0.5 ? -1.0 : 1.0) * e.P("kappa");
        if (kick != 0.0) ++sum.starts_kicked;
        start = Compose(start, {0.0, 0.0, kick});
        last_turn = 0;
        last_dir = m.dir;
      }
    } else if (e.name == "motion_noise_floor") {
      // N(0, sigma^2) per wheel and motion: half the variance as it starts, half as it stops.
      const double h = e.P("sigma") / std::sqrt(2.0);
      ch[m.first].aL += h * n01(g.floor);
      ch[m.first].aR += h * n01(g.floor);
      ch[m.last].aL += h * n01(g.floor);
      ch[m.last].aR += h * n01(g.floor);
    }
    if (m.last + 1 >= n) continue;  // the run ends as the motion stops: no standstill after it
    Pose2& stop = ch[m.last + 1].jump;
    if (e.name == "standstill_motion") {
      const double sxy = e.P("sigma_xy"), sth = e.P("sigma_theta");
      const double along = sxy * n01(g.still), across = sxy * n01(g.still), turn = sth * n01(g.still);
      stop = Compose(stop, {along, across, turn});
      ++sum.standstills;
    } else if (e.name == "stop_slide") {
      if (m.turn) stop = Compose(stop, {0.0, 0.0, m.turn_sign * e.P("a") * m.stop_rate * m.stop_rate});
      else stop = Compose(stop, {m.dir * e.P("d") * m.stop_speed * m.stop_speed, 0.0, 0.0});
      ++sum.standstills;
    }
  }
}

/// The recorded wheels' dead-reckoning pose at time t (nominal geometry;
/// still before the first and after the last sample).
inline Pose2 WheelPoseAt(const RecordedRun& r, const std::vector<Pose2>& odo, double t, double b) {
  if (t <= r.t.front()) return odo.front();
  if (t >= r.t.back()) return odo.back();
  const auto k = static_cast<std::size_t>(std::upper_bound(r.t.begin(), r.t.end(), t) - r.t.begin());
  const double f = (t - r.t[k - 1]) / std::max(r.t[k] - r.t[k - 1], 1e-12);
  return Compose(odo[k - 1], Arc(f * (r.wl[k] - r.wl[k - 1]), f * (r.wr[k] - r.wr[k - 1]), b));
}

/// Injects the options' effects into one run's ground truth (in place).
inline void InjectRun(RecordedRun& r, const InjectOptions& o, int run_index, Streams& g, InjectSummary& sum) {
  const int n = static_cast<int>(r.t.size());
  if (n < 2) return;
  const double b = o.wheelbase_m;
  const auto motions = SegmentMotions(r, o);
  sum.motions += static_cast<int>(motions.size());
  for (const Motion& m : motions) sum.spot_turns += m.turn ? 1 : 0;
  // The castor's starts: every start after min_still_s of still encoders (see the file comment).
  InjectOptions literal = o;
  literal.min_travel_m = 0.0;
  const auto starts = SegmentMotions(r, literal);
  std::vector<IntervalChange> ch(static_cast<std::size_t>(n));
  for (const InjectEffect& e : o.effects) {
    WheelChanges(r, motions, e, run_index, g, ch, sum);
    const bool castor = e.name == "castor_kick" || e.name == "castor_swivel";
    StartStopChanges(r, castor ? starts : motions, e, g, ch, sum);
  }
  // Effects on the true motion: T'_k = T'_{k-1} J_k m1_k m0_k^-1 D_k.  A sample
  // without ground truth is bridged by the recorded wheels' motion.
  std::vector<Pose2> est(static_cast<std::size_t>(n)), out(static_cast<std::size_t>(n));
  est[0] = r.has_gt[0] ? r.gt[0] : Pose2{};
  out[0] = est[0];
  for (int k = 1; k < n; ++k) {
    const double sL = r.wl[k] - r.wl[k - 1], sR = r.wr[k] - r.wr[k - 1];
    const IntervalChange& c = ch[k];
    Pose2 m1 = Arc(sL * c.fL + c.aL, sR * c.fR + c.aR, b);
    m1.th *= c.turn_scale;
    const Pose2 m0 = Arc(sL, sR, b);
    est[k] = r.has_gt[k] ? r.gt[k] : Compose(est[k - 1], m0);
    const Pose2 d = Compose(Inverse(est[k - 1]), est[k]);
    out[k] = Compose(out[k - 1], Compose(Compose(c.jump, Compose(m1, Inverse(m0))), d));
  }
  // Effects on the measurement: clocks, then the marker.
  double tau = 0.0;
  for (const InjectEffect& e : o.effects) {
    if (e.name == "time_offset") tau += e.P("tau");
    if (e.name == "run_time_offset") {
      const double ti = std::normal_distribution<double>(0.0, e.P("tau_sd"))(g.clock);
      sum.run_taus_s.push_back(ti);
      tau += ti;
    }
  }
  if (tau != 0.0) {
    std::vector<Pose2> odo(static_cast<std::size_t>(n));
    for (int k = 1; k < n; ++k) odo[k] = Compose(odo[k - 1], Arc(r.wl[k] - r.wl[k - 1], r.wr[k] - r.wr[k - 1], b));
    for (int k = 0; k < n; ++k)
      out[k] = Compose(out[k], Compose(Inverse(odo[k]), WheelPoseAt(r, odo, r.t[k] - tau, b)));
  }
  for (const InjectEffect& e : o.effects)
    if (e.name == "gt_offset")
      for (auto& p : out) p = Compose(p, {e.P("dx"), e.P("dy"), 0.0});
  for (int k = 0; k < n; ++k) {
    if (!r.has_gt[k]) continue;
    sum.max_position_change_m = std::max(sum.max_position_change_m, std::hypot(out[k].x - r.gt[k].x, out[k].y - r.gt[k].y));
    sum.max_heading_change_rad = std::max(sum.max_heading_change_rad, std::abs(out[k].th - r.gt[k].th));
  }
  r.gt = out;
}

/// A trajectory CSV (docs/formats.md) as text: comment lines, the header,
/// the rows split at commas; the columns the injection needs.
struct TrajectoryTable {
  std::vector<std::string> comments, header;
  std::vector<std::vector<std::string>> rows;
  int run = -1, t = -1, left = -1, right = -1, x = -1, y = -1, th = -1;
  bool ticks = true;  ///< ticks_left/right (else dist_left_m/right_m)
};

inline std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> f;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) f.push_back(cell);
  if (!line.empty() && line.back() == ',') f.emplace_back();
  return f;
}

inline TrajectoryTable ReadTrajectory(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path + ": cannot open");
  TrajectoryTable tab;
  std::string line;
  int line_no = 0;
  while (std::getline(f, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    if (line[0] == '#') {
      if (tab.header.empty()) tab.comments.push_back(line);
      continue;
    }
    if (tab.header.empty()) {
      tab.header = SplitCsv(line);
      continue;
    }
    auto row = SplitCsv(line);
    if (row.size() != tab.header.size())
      throw std::runtime_error(path + ":" + std::to_string(line_no) + ": " + std::to_string(row.size()) +
                               " fields, the header has " + std::to_string(tab.header.size()));
    tab.rows.push_back(std::move(row));
  }
  const auto col = [&](const std::string& name) {
    const auto it = std::find(tab.header.begin(), tab.header.end(), name);
    return it == tab.header.end() ? -1 : static_cast<int>(it - tab.header.begin());
  };
  tab.run = col("run"), tab.t = col("t_s"), tab.x = col("x_gt_m"), tab.y = col("y_gt_m"), tab.th = col("theta_gt_rad");
  tab.left = col("ticks_left"), tab.right = col("ticks_right");
  if (tab.left < 0) tab.ticks = false, tab.left = col("dist_left_m"), tab.right = col("dist_right_m");
  if (tab.run < 0 || tab.t < 0 || tab.x < 0 || tab.y < 0 || tab.th < 0 || tab.left < 0 || tab.right < 0)
    throw std::runtime_error(path + ":1: a trajectory CSV needs run, t_s, ticks_left/right (or dist_left_m/right_m), "
                             "x_gt_m, y_gt_m, theta_gt_rad");
  return tab;
}

inline double Number(const std::string& s) {
  if (s.empty()) return std::nan("");
  return std::stod(s);
}

/// Injects into every run of the table (runs in file order), in place.
inline InjectSummary InjectTable(TrajectoryTable& tab, const InjectOptions& o) {
  InjectSummary sum;
  Streams g(o.seed);
  const double per_tick_L = tab.ticks ? 3.14159265358979323846 * o.diameter_left_m / o.ticks_per_rev : 1.0;
  const double per_tick_R = tab.ticks ? 3.14159265358979323846 * o.diameter_right_m / o.ticks_per_rev : 1.0;
  for (std::size_t a = 0; a < tab.rows.size();) {
    std::size_t e = a;
    while (e < tab.rows.size() && tab.rows[e][tab.run] == tab.rows[a][tab.run]) ++e;
    RecordedRun r;
    for (std::size_t i = a; i < e; ++i) {
      const auto& row = tab.rows[i];
      r.t.push_back(Number(row[tab.t]));
      r.wl.push_back(Number(row[tab.left]) * per_tick_L);
      r.wr.push_back(Number(row[tab.right]) * per_tick_R);
      const Pose2 p{Number(row[tab.x]), Number(row[tab.y]), Number(row[tab.th])};
      r.has_gt.push_back(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.th));
      r.gt.push_back(p);
    }
    InjectRun(r, o, o.first_run_index + sum.runs, g, sum);
    ++sum.runs;
    for (std::size_t i = a; i < e; ++i) {
      if (!r.has_gt[i - a]) continue;
      char buf[3][40];
      std::snprintf(buf[0], sizeof buf[0], "%.9g", r.gt[i - a].x);
      std::snprintf(buf[1], sizeof buf[1], "%.9g", r.gt[i - a].y);
      std::snprintf(buf[2], sizeof buf[2], "%.9g", r.gt[i - a].th);
      tab.rows[i][tab.x] = buf[0];
      tab.rows[i][tab.y] = buf[1];
      tab.rows[i][tab.th] = buf[2];
    }
    a = e;
  }
  return sum;
}

inline void WriteTrajectory(const TrajectoryTable& tab, const std::string& path) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp);
    for (const auto& c : tab.comments) f << c << '\n';
    for (std::size_t i = 0; i < tab.header.size(); ++i) f << (i ? "," : "") << tab.header[i];
    f << '\n';
    for (const auto& row : tab.rows) {
      for (std::size_t i = 0; i < row.size(); ++i) f << (i ? "," : "") << row[i];
      f << '\n';
    }
    if (!f) throw std::runtime_error(path + ": cannot write");
  }
  std::rename(tmp.c_str(), path.c_str());
}

}  // namespace umbmark_bench
