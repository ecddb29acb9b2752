// One run's poses from scan registration (see scan_track.hpp).
#include "scan/scan_track.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <memory>
#include <optional>

#include <fmt/format.h>

#include "core/angles.hpp"
#include "core/errors.hpp"

namespace umbmark::scan {

namespace {

double Seconds(std::int64_t t_ns) { return static_cast<double>(t_ns) * 1e-9; }

// Axle motion from lidar motion: axle0_T_axle = axle_T_lidar * lidar0_T_lidar * lidar_T_axle.
Pose2 AxleFromLidar(const Pose2& mount, const Pose2& lidar) { return Compose(Compose(mount, lidar), Inverse(mount)); }
Pose2 LidarFromAxle(const Pose2& mount, const Pose2& axle) { return Compose(Compose(Inverse(mount), axle), mount); }

// J C J^T for the map lidar -> axle at `lidar` (numerical Jacobian).
std::array<double, 9> AxleCovariance(const Pose2& mount, const Pose2& lidar, const std::array<double, 9>& c) {
  double j[3][3];
  const Pose2 base = AxleFromLidar(mount, lidar);
  for (int k = 0; k < 3; ++k) {
    Pose2 d = lidar;
    const double h = 1e-6;
    (k == 0 ? d.x : k == 1 ? d.y : d.theta) += h;
    const Pose2 a = AxleFromLidar(mount, d);
    j[0][k] = (a.x - base.x) / h;
    j[1][k] = (a.y - base.y) / h;
    j[2][k] = (a.theta - base.theta) / h;
  }
  std::array<double, 9> out{};
  for (int r = 0; r < 3; ++r)
    for (int s = 0; s < 3; ++s) {
      double v = 0.0;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) v += j[r][a] * c[static_cast<std::size_t>(3 * a + b)] * j[s][b];
      out[static_cast<std::size_t>(3 * r + s)] = v;
    }
  return out;
}

}  // namespace

std::string TrackOptions::Validate() const {
  if (const std::string e = match.Validate(); !e.empty()) return "match." + e;
  if (!(keyframe_distance_m > 0.0)) return fmt::format("keyframe_distance_m = {}: must be > 0", keyframe_distance_m);
  if (!(keyframe_angle_rad > 0.0)) return fmt::format("keyframe_angle_rad = {}: must be > 0", keyframe_angle_rad);
  if (!(keyframe_overlap >= 0.0 && keyframe_overlap <= 1.0)) return fmt::format("keyframe_overlap = {}: must be in [0, 1]", keyframe_overlap);
  if (!(min_end_overlap >= 0.0 && min_end_overlap <= 1.0)) return fmt::format("min_end_overlap = {}: must be in [0, 1]", min_end_overlap);
  if (!(still_moved_m > 0.0)) return fmt::format("still_moved_m = {}: must be > 0", still_moved_m);
  if (min_pairs < 3) return fmt::format("min_pairs = {}: must be >= 3", min_pairs);
  if (max_still_scans < 1) return fmt::format("max_still_scans = {}: must be >= 1", max_still_scans);
  if (still_model_scans < 1) return fmt::format("still_model_scans = {}: must be >= 1", still_model_scans);
  if (!(still_min_move_m > 0.0)) return fmt::format("still_min_move_m = {}: must be > 0", still_min_move_m);
  if (!(still_min_turn_rad > 0.0)) return fmt::format("still_min_turn_rad = {}: must be > 0", still_min_turn_rad);
  if (!(max_dilution > 0.0)) return fmt::format("max_dilution = {}: must be > 0", max_dilution);
  if (!std::isfinite(mount.x) || !std::isfinite(mount.y) || !std::isfinite(mount.theta)) return "mount: must be finite";
  return {};
}

struct RunTracker::Impl {
  RunWindow w;
  const std::function<Pose2(std::int64_t)>& odometry;
  TrackOptions o;
  std::deque<LaserScan> before_scans;  // still before the run, nearest it last
  std::vector<LaserScan> after_scans;   // still after the run, nearest it first
  ScanAverager before, after;
  std::unique_ptr<ScanModel> reference, keyframe_model;  // keyframe_model null: the reference
  Pose2 keyframe, prev;
  std::int64_t prev_t = 0;
  std::vector<StampedPose> lidar;  // chained lidar poses relative to the reference
  double scatter_xy = 0.0, scatter_theta = 0.0;  // sums of squared still-scan deviations (axle frame)
  std::size_t scatter_n = 0;
  TrackResult out;

  Impl(const RunWindow& window, const std::function<Pose2(std::int64_t)>& odo, const TrackOptions& opt)
      : w(window), odometry(odo), o(opt), prev_t(window.t_start_ns) {}

  // Registers and checks; throws for a failed or degenerate registration.
  MatchResult Register(const ScanModel& model, const std::vector<Point2>& pts, const Pose2& guess, std::int64_t t_ns,
                       const char* what) {
    MatchResult m = MatchScan(model, pts, guess, o.match);
    ++out.registrations;
    out.iterations += static_cast<std::size_t>(m.iterations);
    if (m.pairs < o.min_pairs)
      throw RegistrationFailed(t_ns, fmt::format("the {} pairs only {} of its {} points with the scan it is registered "
                                                 "against (at least {} needed: walls out of range, or the robot moved "
                                                 "too far between scans)", what, m.pairs, m.points, o.min_pairs));
    const auto dirs = UndeterminedDirections(m.information, m.pairs, o.mount.theta, o.max_dilution);
    if (!dirs.empty())
      throw DegenerateScene(t_ns, dirs, fmt::format("the scene does not determine the pose {} at the {} (a corridor, "
                                                    "or walls beyond the lidar's range: registration dilution of "
                                                    "precision above {})", fmt::join(dirs, " and "), what, o.max_dilution));
    out.max_residual_sd_m = std::max(out.max_residual_sd_m, m.residual_sd_m);
    return m;
  }

  // Lidar motion the wheels predict between two times.
  Pose2 Predict(std::int64_t from, std::int64_t to) const {
    return LidarFromAxle(o.mount, RelativeTo(odometry(from), odometry(to)));
  }

  // How many of `scans` (nearest the run first) were taken from the pose of
  // the first: (1) the median range change against the first at most
  // still_moved_m (a carry: centimetres); (2) registered against the average
  // of the nearest few, within 4 standard deviations of their registration
  // (at least 2 mm, 1 mrad; a slow set-down, a nudge). The walk stops at the
  // first scan that fails, and at one that fails (2) when the next one
  // outward fails too (a single noisy registration is not a move). The kept
  // scans' deviations make the still scatter.
  std::size_t FromOnePose(const std::vector<const LaserScan*>& scans) {
    std::size_t k = 0;
    while (k < scans.size() && MedianRangeChange(*scans[k], *scans[0]) <= o.still_moved_m) ++k;
    if (k < 2) return k;
    ScanAverager near;
    for (std::size_t i = 0; i < std::min<std::size_t>(k, o.still_model_scans); ++i) near.Add(*scans[i]);
    const ScanModel model(near.Mean());
    std::vector<bool> off(k, false);
    std::vector<Pose2> dev(k);
    for (std::size_t i = 0; i < k; ++i) {
      const MatchResult m = MatchScan(model, ScanPoints(*scans[i]), Pose2{}, o.match);
      ++out.registrations;
      const auto c = m.Covariance();
      const double sd_xy = std::sqrt(std::max(0.0, 0.5 * (c[0] + c[4]))), sd_th = std::sqrt(std::max(0.0, c[8]));
      dev[i] = AxleFromLidar(o.mount, m.pose);
      off[i] = m.pairs < o.min_pairs || std::hypot(m.pose.x, m.pose.y) > std::max(o.still_min_move_m, 4.0 * sd_xy) ||
               std::abs(m.pose.theta) > std::max(o.still_min_turn_rad, 4.0 * sd_th);
    }
    std::size_t kept = k;
    for (std::size_t i = 1; i < k; ++i)
      if (off[i] && (i + 1 == k || off[i + 1])) {
        kept = i;
        break;
      }
    for (std::size_t i = 0; i < kept; ++i) {
      scatter_xy += 0.5 * (dev[i].x * dev[i].x + dev[i].y * dev[i].y);
      scatter_theta += dev[i].theta * dev[i].theta;
      ++scatter_n;
    }
    return kept;
  }

  // The still scans before the run from the pose it starts from (walking
  // back from the scan nearest the run); their average is the reference.
  void SelectBefore() {
    if (before_scans.empty()) return;
    std::vector<const LaserScan*> order;
    for (auto it = before_scans.rbegin(); it != before_scans.rend(); ++it) order.push_back(&*it);
    const std::size_t k = FromOnePose(order);
    if (k < order.size()) {
      ++out.still_moved;
      out.moved_before_ns = order[k]->t_ns;
    }
    out.still_before_from_ns = order[k - 1]->t_ns;
    out.still_before_to_ns = order[0]->t_ns;
    for (std::size_t i = 0; i < k; ++i) before.Add(*order[i]);
    before_scans.clear();
  }

  // The still scans after the run from the pose it ends at.
  void SelectAfter() {
    if (after_scans.empty()) return;
    std::vector<const LaserScan*> order;
    for (const auto& a : after_scans) order.push_back(&a);
    const std::size_t k = FromOnePose(order);
    if (k < order.size()) {
      ++out.still_moved;
      out.moved_after_ns = order[k]->t_ns;
    }
    out.still_after_from_ns = order[0]->t_ns;
    out.still_after_to_ns = order[k - 1]->t_ns;
    for (std::size_t i = 0; i < k; ++i) after.Add(*order[i]);
    after_scans.clear();
  }

  void EnsureReference() {
    if (reference) return;
    SelectBefore();
    if (before.count() == 0)
      throw RegistrationFailed(w.t_start_ns, fmt::format("no scan while the robot stood still before the run ({:.3f} s "
                                                         "of standstill): no reference to register against; record "
                                                         "a few seconds standing still before every run",
                                                         Seconds(w.t_start_ns - w.still_from_ns)));
    reference = std::make_unique<ScanModel>(before.Mean());
  }

  void Chain(const LaserScan& s) {
    EnsureReference();
    const Pose2 predicted = Compose(prev, Predict(prev_t, s.t_ns));
    const ScanModel& model = keyframe_model ? *keyframe_model : *reference;
    const MatchResult m = Register(model, ScanPoints(s), RelativeTo(keyframe, predicted), s.t_ns, "scan");
    const Pose2 pose = Compose(keyframe, m.pose);
    lidar.push_back({s.t_ns, pose});
    ++out.chained;
    prev = pose;
    prev_t = s.t_ns;
    if (std::hypot(m.pose.x, m.pose.y) > o.keyframe_distance_m || std::abs(m.pose.theta) > o.keyframe_angle_rad ||
        m.PairedFraction() < o.keyframe_overlap) {
      keyframe_model = std::make_unique<ScanModel>(s);
      keyframe = pose;
      ++out.keyframes;
    }
  }

  // The end pose from the averaged still scans after the run.
  Pose2 End(const Pose2& guess, std::array<double, 9>& cov) {
    const LaserScan end_scan = after.Mean();
    const std::vector<Point2> pts = ScanPoints(end_scan);
    const char* what = "first still scan after the run";
    MatchResult m = MatchScan(*reference, pts, guess, o.match);
    out.end_direct = m.PairedFraction() >= o.min_end_overlap && m.pairs >= o.min_pairs;
    Pose2 end;
    if (out.end_direct) {
      m = Register(*reference, pts, m.pose, end_scan.t_ns, what);
      end = m.pose;
    } else {
      const ScanModel& model = keyframe_model ? *keyframe_model : *reference;
      m = Register(model, pts, RelativeTo(keyframe, guess), end_scan.t_ns, what);
      end = Compose(keyframe, m.pose);
    }
    cov = m.Covariance();
    end.theta = guess.theta + WrapAngle(end.theta - guess.theta);
    return end;
  }
};

RunTracker::RunTracker(const RunWindow& window, const std::function<Pose2(std::int64_t)>& odometry,
                       const TrackOptions& options) {
  if (const std::string e = options.Validate(); !e.empty()) throw InvalidOptions(e);
  if (!(window.still_from_ns <= window.t_start_ns && window.t_start_ns < window.t_end_ns &&
        window.t_end_ns <= window.still_to_ns))
    throw InvalidOptions("RunWindow: needs still_from <= t_start < t_end <= still_to");
  impl_ = std::make_unique<Impl>(window, odometry, options);
}
RunTracker::~RunTracker() = default;
RunTracker::RunTracker(RunTracker&&) noexcept = default;
RunTracker& RunTracker::operator=(RunTracker&&) noexcept = default;
const RunWindow& RunTracker::window() const { return impl_->w; }

// Still scans are kept (before the run the ones nearest it, after it the
// first ones); the group taken from the run's start pose is chosen when the
// run begins (SelectBefore), the one from its end pose when it finishes
// (SelectAfter). A scan between t_start and t_end is chained.
void RunTracker::Add(const LaserScan& s) {
  Impl& d = *impl_;
  if (s.t_ns < d.w.still_from_ns || s.t_ns > d.w.still_to_ns) return;
  // A still scan's whole sweep lies before the run starts (its last ray too).
  const double sweep_s = std::abs(s.time_increment) * static_cast<double>(s.ranges.empty() ? 0 : s.ranges.size() - 1);
  if (s.t_ns + static_cast<std::int64_t>(std::llround(sweep_s * 1e9)) <= d.w.t_start_ns) {
    d.before_scans.push_back(s);
    if (d.before_scans.size() > d.o.max_still_scans) d.before_scans.pop_front();
  } else if (s.t_ns < d.w.t_end_ns) {
    if (d.o.deskew && s.time_increment != 0.0 && s.ranges.size() > 1) {
      // The sweep as seen from where its first ray was taken (laser_scan.hpp).
      const auto to = s.t_ns + static_cast<std::int64_t>(std::llround(sweep_s * 1e9));
      d.Chain(Deskew(s, d.Predict(s.t_ns, to)));
    } else {
      d.Chain(s);
    }
  } else if (d.after_scans.size() < d.o.max_still_scans) {
    d.after_scans.push_back(s);
  }
}

// End registration, still scatter, then the poses in the axle frame at
// increasing times (the diagram of scan_track.hpp, last steps).
TrackResult RunTracker::Finish() {
  Impl& d = *impl_;
  d.EnsureReference();
  d.SelectAfter();
  TrackResult& out = d.out;
  out.still_before = d.before.count();
  out.still_after = d.after.count();
  const Pose2 guess = Compose(d.prev, d.Predict(d.prev_t, d.w.t_end_ns));
  Pose2 end_lidar = guess;
  std::array<double, 9> end_cov{};
  if (d.after.count() > 0) end_lidar = d.End(guess, end_cov);
  if (d.scatter_n > 0) {
    out.still_sd_xy_m = std::sqrt(d.scatter_xy / static_cast<double>(d.scatter_n));
    out.still_sd_theta_rad = std::sqrt(d.scatter_theta / static_cast<double>(d.scatter_n));
  }
  out.end = AxleFromLidar(d.o.mount, end_lidar);
  out.end_covariance = AxleCovariance(d.o.mount, end_lidar, end_cov);
  auto add = [&](std::int64_t t, const Pose2& p) {
    if (out.poses.empty() || t > out.poses.back().t_ns) out.poses.push_back({t, p});
  };
  if (d.w.still_from_ns < d.w.t_start_ns) add(d.w.still_from_ns, Pose2{});
  add(d.w.t_start_ns, Pose2{});
  for (const auto& sp : d.lidar) add(sp.t_ns, AxleFromLidar(d.o.mount, sp.pose));
  add(d.w.t_end_ns, out.end);
  if (d.w.still_to_ns > d.w.t_end_ns) add(d.w.still_to_ns, out.end);
  return std::move(out);
}

TrackResult TrackRun(const RunScans& scans, const std::function<Pose2(std::int64_t)>& odometry, const TrackOptions& o) {
  RunWindow w{scans.t_start_ns, scans.t_start_ns, scans.t_end_ns, scans.t_end_ns};
  if (!scans.before.empty()) w.still_from_ns = std::min(w.still_from_ns, scans.before.front()->t_ns);
  if (!scans.after.empty()) w.still_to_ns = std::max(w.still_to_ns, scans.after.back()->t_ns);
  RunTracker tracker(w, odometry, o);
  for (const auto* list : {&scans.before, &scans.during, &scans.after})
    for (const LaserScan* s : *list) tracker.Add(*s);
  return tracker.Finish();
}

}  // namespace umbmark::scan
