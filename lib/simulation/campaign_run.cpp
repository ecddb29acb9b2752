// Run simulator of the campaign generator (see campaign_run.hpp).
#include "simulation/campaign_run.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "effects/registry.hpp"
#include "model/true_robot.hpp"
#include "simulation/rng.hpp"

namespace umbmark::sim {

namespace {

/// N(0, 1) variates from one stream, two at a time (Box-Muller, rng.hpp).
class NormalSource {
 public:
  explicit NormalSource(std::uint64_t seed) : gen_(seed) {}
  double Next() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double z0 = 0.0, z1 = 0.0;
    const std::uint64_t a = gen_.Next();
    const std::uint64_t b = gen_.Next();
    NormalPairFromBits(a, b, z0, z1);
    spare_ = z1;
    has_spare_ = true;
    return z0;
  }
  /// Exponential with mean 1.
  double Exponential() { return -std::log(1.0 - gen_.Uniform()); }
  double Uniform() { return gen_.Uniform(); }

 private:
  Xoshiro256pp gen_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

/// Wheel noise (Chong & Kleeman eq. 4, left/right correlation rho
/// [correlated_noise]) and bumps (N(0, sigma_b^2) per bump, bumps arriving
/// per wheel as a Poisson process in travelled distance [bump_outliers]) on
/// each step's true wheel travel, from the run's own streams.
class WheelDisturbance {
 public:
  WheelDisturbance(const RunTruth& truth, std::uint64_t seed, std::uint64_t run_index)
      : wheel_rng_(StreamSeed(seed, run_index, kCampaignStreamWheelNoise)),
        bump_rng_(StreamSeed(seed, run_index, kCampaignStreamBumps)),
        k_{truth.k_L, truth.k_R},
        rho_(truth.effects.noise_rho),
        rho_c_(std::sqrt(std::max(0.0, 1.0 - rho_ * rho_))),
        bump_rate_(truth.effects.bump_rate),
        bump_sigma_(truth.effects.bump_sigma),
        bumps_(bump_rate_ > 0.0 && bump_sigma_ > 0.0) {
    if (bumps_) {
      to_bump_[0] = bump_rng_.Exponential() / bump_rate_;
      to_bump_[1] = bump_rng_.Exponential() / bump_rate_;
    }
  }

  /// Adds the noise and the bumps of one step to travel[0] (left), travel[1]
  /// (right) [m]; counts the bumps in out.
  void Apply(double (&travel)[2], SimulatedRun& out) {
    const double z0 = wheel_rng_.Next(), z1 = wheel_rng_.Next();
    const double mean_abs[2] = {std::abs(travel[0]), std::abs(travel[1])};
    travel[0] += k_[0] * std::sqrt(mean_abs[0]) * z0;
    travel[1] += k_[1] * std::sqrt(mean_abs[1]) * (rho_ * z0 + rho_c_ * z1);
    if (!bumps_) return;
    for (int w = 0; w < 2; ++w) {
      double left_to_roll = mean_abs[w];
      while (to_bump_[w] <= left_to_roll) {
        travel[w] += bump_sigma_ * bump_rng_.Next();
        left_to_roll -= to_bump_[w];
        to_bump_[w] = bump_rng_.Exponential() / bump_rate_;
        (w == 0 ? out.bumps_left : out.bumps_right) += 1;
      }
      to_bump_[w] -= left_to_roll;
    }
  }

 private:
  NormalSource wheel_rng_, bump_rng_;
  double k_[2];
  double rho_, rho_c_;
  double bump_rate_, bump_sigma_;
  bool bumps_;
  double to_bump_[2] = {std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
};

/// One executed step: enough to re-evaluate the pose at any time inside it.
struct StepRecord {
  double ta = 0.0, tb = 0.0;
  Pose2 start, end;
  double left_m = 0.0, right_m = 0.0;  ///< true ground travel (noise and bumps included)
  double heading_factor = 1.0;         ///< 1 - k inside spot turns
  double slide_x_m = 0.0, slide_y_m = 0.0;
};

/// The true robot's step (TrueStep) plus a sideways slide (floor_slope).
Pose2 AdvancePose(const Pose2& p, double l, double r, double wheelbase, double heading_factor, double slide_x,
                  double slide_y) {
  const Pose2 q = TrueStep(p, l, r, wheelbase, heading_factor);
  return {q.x + slide_x, q.y + slide_y, q.theta};
}

/// The plan's sample times (given, or every 1/sample_rate_hz from 0 until
/// the plan ends), checked against the plan. Throws InvalidOptions.
std::vector<double> SampleTimes(const RunPlan& plan) {
  double total = 0.0;
  for (const auto& m : plan.motions) {
    if (!(m.duration_s >= 0.0) || !std::isfinite(m.duration_s))
      throw InvalidOptions(fmt::format("SimulateLoggedRun: motion duration {} must be finite and >= 0", m.duration_s));
    total += m.duration_s;
  }
  std::vector<double> ts = plan.sample_times;
  if (ts.empty()) {
    if (!(plan.sample_rate_hz > 0.0)) throw InvalidOptions("SimulateLoggedRun: sample_rate_hz must be > 0");
    const double dt = 1.0 / plan.sample_rate_hz;
    const auto k = static_cast<std::size_t>(std::ceil(total / dt - 1e-9));
    ts.resize(k + 1);
    for (std::size_t j = 0; j <= k; ++j) ts[j] = static_cast<double>(j) * dt;
  }
  if (ts.front() != 0.0) throw InvalidOptions("SimulateLoggedRun: the first sample time must be 0");
  for (std::size_t j = 1; j < ts.size(); ++j)
    if (!(ts[j] > ts[j - 1])) throw InvalidOptions("SimulateLoggedRun: sample times must increase strictly");
  if (ts.back() < total - 1e-9) throw InvalidOptions("SimulateLoggedRun: the samples end before the plan does");

  return ts;
}

/// True pose at any time (time_offset): the step containing it, partially
/// executed; the start pose before the first step, the last pose after it.
Pose2 PoseAt(const std::vector<StepRecord>& steps, double time, double wheelbase) {
  if (steps.empty() || time < steps.front().ta) return Pose2{};
  auto it = std::upper_bound(steps.begin(), steps.end(), time, [](double v, const StepRecord& s) { return v < s.ta; });
  const StepRecord& s = *(it - 1);
  if (time >= s.tb || s.tb <= s.ta) return s.end;
  const double f = (time - s.ta) / (s.tb - s.ta);
  return AdvancePose(s.start, f * s.left_m, f * s.right_m, wheelbase, s.heading_factor, f * s.slide_x_m,
                     f * s.slide_y_m);
}

/// What the logger writes at the sample times: encoder counts (or nominal
/// travel) and ground truth with the effects' point and heading
/// (Effect::GroundTruthPoint) and measurement noise (from gt_rng); delay:
/// the ground truth's clock for this run (Effect::GroundTruthDelay, summed).
void WriteLog(const std::vector<double>& ts, const std::vector<Pose2>& sample_pose,
              const std::vector<double> (&sample_p)[2], const std::vector<StepRecord>& steps, const RunTruth& truth,
              double delay, NormalSource& gt_rng, TrajectoryRun& run) {
  // The point and heading the ground truth reports (each effect's
  // GroundTruthPoint: a marker off the axle, a rigid body's yaw).
  double gt_dx = 0.0, gt_dy = 0.0, gt_dtheta = 0.0;
  for (const effects::Effect* e : effects::All()) e->GroundTruthPoint(truth.effects, gt_dx, gt_dy, gt_dtheta);
  const std::size_t n = ts.size();
  run.t_s = ts;
  run.lines.assign(n, 0);
  run.gt_x_m.resize(n);
  run.gt_y_m.resize(n);
  run.gt_theta_rad.resize(n);
  if (truth.ticks) {
    run.ticks_left.resize(n);
    run.ticks_right.resize(n);
  } else {
    run.dist_left_m.resize(n);
    run.dist_right_m.resize(n);
  }
  for (std::size_t j = 0; j < n; ++j) {
    if (truth.ticks) {
      run.ticks_left[j] = static_cast<std::int64_t>(std::floor(sample_p[0][j]));
      run.ticks_right[j] = static_cast<std::int64_t>(std::floor(sample_p[1][j]));
    } else {
      run.dist_left_m[j] = sample_p[0][j];
      run.dist_right_m[j] = sample_p[1][j];
    }
    const Pose2 q = delay != 0.0 ? PoseAt(steps, ts[j] - delay, truth.true_wheelbase_m) : sample_pose[j];
    const double c = std::cos(q.theta), s = std::sin(q.theta);
    const double nx = gt_rng.Next(), ny = gt_rng.Next(), nt = gt_rng.Next();
    run.gt_x_m[j] = q.x + c * gt_dx - s * gt_dy + truth.gt_sigma_xy_m * nx;
    run.gt_y_m[j] = q.y + s * gt_dx + c * gt_dy + truth.gt_sigma_xy_m * ny;
    run.gt_theta_rad[j] = q.theta + gt_dtheta + truth.gt_sigma_theta_rad * nt;
  }
}

/// Where the plan's motions meet standstills: a motion starts from one (the
/// run's first move, or after a pause that lasts) and stops before one (a
/// pause that lasts, or the run's end); standstill_follows: a lasting pause
/// comes after it (the run's end does not count; standstill_motion).
struct MotionBoundaries {
  std::vector<char> starts, stops, standstill_follows;
};

MotionBoundaries FindBoundaries(const RunPlan& plan) {
  const std::size_t n = plan.motions.size();
  MotionBoundaries b{std::vector<char>(n, 0), std::vector<char>(n, 0), std::vector<char>(n, 0)};
  bool still = true;
  for (std::size_t k = 0; k < n; ++k) {
    const PlannedMotion& m = plan.motions[k];
    if (m.pause) {
      if (m.duration_s > 0.0) still = true;
      continue;
    }
    b.starts[k] = still;
    still = false;
    std::size_t q = k + 1;
    while (q < n && plan.motions[q].pause && !(plan.motions[q].duration_s > 0.0)) ++q;
    b.stops[k] = q == n || plan.motions[q].pause;
    for (q = k + 1; q < n && plan.motions[q].pause; ++q)
      if (plan.motions[q].duration_s > 0.0) {
        b.standstill_follows[k] = 1;
        break;
      }
  }
  return b;
}

/// A motion's sign (PlannedMotion::sign, or from its travel).
int MotionSign(const PlannedMotion& m) {
  if (m.sign != 0) return m.sign;
  if (m.cls == MotionClass::kTurn) return m.right_m - m.left_m >= 0.0 ? 1 : -1;
  return m.left_m + m.right_m >= 0.0 ? 1 : -1;
}

/// Executes a plan step by step (SimulateLoggedRun): the wheel positions,
/// the pose, the executed steps and what each sample sees.
class RunExecutor {
 public:
  RunExecutor(const RunPlan& plan, const RunTruth& truth, std::uint64_t seed, std::uint64_t run_index,
              const std::vector<double>& ts, SimulatedRun& out)
      : plan_(plan),
        truth_(truth),
        fx_(truth.effects),
        ts_(ts),
        out_(out),
        bounds_(FindBoundaries(plan)),
        phase_rng_(StreamSeed(seed, run_index, kCampaignStreamPhase)),
        stand_rng_(StreamSeed(seed, run_index, kCampaignStreamStandstill)),
        floor_rng_(StreamSeed(seed, run_index, kCampaignStreamMotionFloor)),
        swivel_rng_(StreamSeed(seed, run_index, kCampaignStreamSwivel)),
        disturbance_(truth, seed, run_index),
        nominal_per_tick_{truth.nominal_per_tick_left, truth.nominal_per_tick_right},
        true_per_tick_{truth.true_per_tick_left, truth.true_per_tick_right},
        slide_cos_(std::cos(fx_.slope_dir)),
        slide_sin_(std::sin(fx_.slope_dir)) {
    if (truth.ticks) {
      p_[0] = phase_rng_.Uniform();
      p_[1] = phase_rng_.Uniform();
    }
    out.phase_left = p_[0];
    out.phase_right = p_[1];
    steps_.reserve(ts.size() + 2 * plan.motions.size());
    sample_pose_.reserve(ts.size());
    sample_p_[0].reserve(ts.size());
    sample_p_[1].reserve(ts.size());
  }

  /// Runs every motion and pause of the plan.
  void Execute() {
    RecordSamplesUpto(0.0);
    double t = 0.0;
    for (std::size_t mk = 0; mk < plan_.motions.size(); ++mk) {
      const PlannedMotion& m = plan_.motions[mk];
      const double t1 = t + m.duration_s;
      if (m.pause) {
        Rest(t, t1);
      } else {
        coast_.active = false;  // a motion ends any coast
        double p_end[2];
        WheelTargets(m, p_end);
        StartKicks(mk);
        RunSteps(mk, t, p_end);
      }
      t = t1;
    }
    RecordSamplesUpto(ts_.back());
  }

  const std::vector<Pose2>& sample_pose() const { return sample_pose_; }
  const std::vector<double> (&sample_p() const)[2] { return sample_p_; }
  const std::vector<StepRecord>& steps() const { return steps_; }

 private:
  void RecordSamplesUpto(double t) {
    while (next_sample_ < ts_.size() && ts_[next_sample_] <= t + 1e-9) {
      sample_pose_.push_back(pose_);
      sample_p_[0].push_back(p_[0]);
      sample_p_[1].push_back(p_[1]);
      ++next_sample_;
    }
  }

  /// The controller stops each wheel when its count reaches the target
  /// count of the cumulative commanded travel.
  void WheelTargets(const PlannedMotion& m, double (&p_end)[2]) {
    commanded_[0] += m.left_m;
    commanded_[1] += m.right_m;
    for (int w = 0; w < 2; ++w) {
      if (truth_.ticks) {
        const double target = std::round(commanded_[w] / nominal_per_tick_[w]);
        p_end[w] = EncoderStopPosition(target, std::floor(p_[w]), p_[w], kStopBelowTicks);
      } else {
        p_end[w] = commanded_[w];
      }
    }
  }

  /// castor_kick (a start from standstill that is not a spot turn) and
  /// castor_swivel (a straight or arc start after a spot turn or a
  /// reversal) as the motion begins.
  void StartKicks(std::size_t mk) {
    const PlannedMotion& m = plan_.motions[mk];
    if (m.from_standstill && m.cls != MotionClass::kTurn && fx_.castor_kappa != 0.0)
      pose_.theta += (m.left_m + m.right_m >= 0.0 ? 1.0 : -1.0) * fx_.castor_kappa;
    if (!m.motion_start) return;
    const int sign = MotionSign(m);
    if (m.cls != MotionClass::kTurn) {
      if (fx_.swivel_kappa != 0.0) {
        if (last_turn_sign_ != 0)
          pose_.theta += last_turn_sign_ * fx_.swivel_kappa;
        else if (last_drive_sign_ != 0 && sign != last_drive_sign_)
          pose_.theta += (swivel_rng_.Uniform() < 0.5 ? -1.0 : 1.0) * fx_.swivel_kappa;
      }
      last_drive_sign_ = sign;
      last_turn_sign_ = 0;
    } else {
      last_turn_sign_ = sign;
    }
  }

  /// One step's true wheel travel with noise, bumps and start / stop slip.
  void StepTravel(std::size_t mk, bool first_step, bool last, const double (&dp)[2], double (&travel)[2]) {
    for (int w = 0; w < 2; ++w) {
      const double asym = dp[w] < 0.0 ? 1.0 + fx_.asymmetry_a : 1.0;
      travel[w] = dp[w] * true_per_tick_[w] * asym;
    }
    disturbance_.Apply(travel, out_);
    // motion_noise_floor: half its variance in the motion's first step,
    // half in its last (start and stop slip).
    if (fx_.floor_sigma > 0.0) {
      const bool start_slip = bounds_.starts[mk] && first_step, stop_slip = bounds_.stops[mk] && last;
      for (int w = 0; w < 2; ++w) {
        if (start_slip) travel[w] += fx_.floor_sigma * std::sqrt(0.5) * floor_rng_.Next();
        if (stop_slip) travel[w] += fx_.floor_sigma * std::sqrt(0.5) * floor_rng_.Next();
      }
    }
  }

  /// The steps of one motion, from t0 to its end: one per sample interval.
  void RunSteps(std::size_t mk, double t0, const double (&p_end)[2]) {
    const PlannedMotion& m = plan_.motions[mk];
    const double t1 = t0 + m.duration_s;
    const double dp_total[2] = {p_end[0] - p_[0], p_end[1] - p_[1]};
    const double heading_factor = m.cls == MotionClass::kTurn ? 1.0 - fx_.scrub_k : 1.0;
    double ta = t0;
    double done = 0.0;  // fraction of the motion executed
    while (true) {
      double tb = t1;
      if (next_sample_ < ts_.size() && ts_[next_sample_] < t1 - 1e-12 && ts_[next_sample_] > ta) tb = ts_[next_sample_];
      const double f_end = m.duration_s > 0.0 ? (tb - t0) / m.duration_s : 1.0;
      const bool last = tb >= t1;
      double dp[2], travel[2];
      for (int w = 0; w < 2; ++w) dp[w] = last ? p_end[w] - p_[w] : (f_end - done) * dp_total[w];
      StepTravel(mk, ta == t0, last, dp, travel);
      StepRecord s;
      s.ta = ta;
      s.tb = tb;
      s.start = pose_;
      s.left_m = travel[0];
      s.right_m = travel[1];
      s.heading_factor = heading_factor;
      const double slope = fx_.slope_g * 0.5 * (std::abs(travel[0]) + std::abs(travel[1]));
      s.slide_x_m = slope * slide_cos_;
      s.slide_y_m = slope * slide_sin_;
      pose_ = AdvancePose(pose_, travel[0], travel[1], truth_.true_wheelbase_m, heading_factor, s.slide_x_m,
                          s.slide_y_m);
      s.end = pose_;
      steps_.push_back(s);
      p_[0] += dp[0];
      p_[1] += dp[1];
      done = f_end;
      if (last) {
        p_[0] = p_end[0];
        p_[1] = p_end[1];
        StopEffects(mk, tb);
      }
      RecordSamplesUpto(tb);
      if (last) break;
      ta = tb;
    }
  }

  /// An instantaneous change of the true pose at time t (a step of no
  /// duration, so that the pose at any time sees it).
  void Jump(const Pose2& to, double t) {
    StepRecord s;
    s.ta = s.tb = t;
    s.start = pose_;
    pose_ = to;
    s.end = pose_;
    steps_.push_back(s);
  }

  /// At the end of motion mk (time t): standstill_motion, then stop_slide.
  void StopEffects(std::size_t mk, double t) {
    const PlannedMotion& m = plan_.motions[mk];
    // standstill_motion: the robot settles as the standstill begins.
    if ((fx_.stand_sigma_xy > 0.0 || fx_.stand_sigma_theta > 0.0) && bounds_.stops[mk] &&
        bounds_.standstill_follows[mk]) {
      const double nx = fx_.stand_sigma_xy * stand_rng_.Next(), ny = fx_.stand_sigma_xy * stand_rng_.Next();
      const double nt = fx_.stand_sigma_theta * stand_rng_.Next();
      const double c = std::cos(pose_.theta), sn = std::sin(pose_.theta);
      Jump({pose_.x + c * nx - sn * ny, pose_.y + sn * nx + c * ny, pose_.theta + nt}, t);
    }
    // stop_slide: the chassis coasts on at the speed the motion ended with,
    // through the pause that follows (Coast).
    if ((fx_.slide_d == 0.0 && fx_.slide_a == 0.0) || !m.motion_end || !bounds_.stops[mk]) return;
    const double duration = m.duration_s > 0.0 ? m.duration_s : 1.0;
    double rate[2] = {std::isfinite(m.end_rate_left) ? m.end_rate_left : m.left_m / duration,
                      std::isfinite(m.end_rate_right) ? m.end_rate_right : m.right_m / duration};
    for (int w = 0; w < 2; ++w)
      rate[w] *= true_per_tick_[w] / nominal_per_tick_[w] * (rate[w] < 0.0 ? 1.0 + fx_.asymmetry_a : 1.0);
    coast_ = {};
    coast_.t0 = t;
    coast_.turn = m.cls == MotionClass::kTurn;
    coast_.rate = coast_.turn ? (rate[1] - rate[0]) / truth_.true_wheelbase_m : 0.5 * (rate[0] + rate[1]);
    coast_.k = coast_.turn ? fx_.slide_a : fx_.slide_d * (coast_.rate < 0.0 ? 1.0 + fx_.slide_back : 1.0);
    // After an arc the heading turns on by arc w/v per metre coasted.
    if (!coast_.turn && coast_.rate != 0.0)
      coast_.curvature = fx_.slide_arc * (rate[1] - rate[0]) / truth_.true_wheelbase_m / coast_.rate;
    coast_.active = coast_.k > 0.0 && coast_.rate != 0.0;
  }

  /// The coast of stop_slide: from t0, uniform deceleration 1 / (2 k)
  /// (Coulomb friction) from `rate` until it rests after 2 k |rate| s,
  /// having covered k rate |rate| (m along the heading, or rad of turn).
  struct Coast {
    bool active = false, turn = false;
    double t0 = 0.0, rate = 0.0, k = 0.0;
    double curvature = 0.0;  ///< heading turned per metre coasted (stop_slide.arc w/v)
    double Progress(double t) const {
      const double v = std::abs(rate), tau = std::clamp(t - t0, 0.0, 2.0 * k * v);
      return (rate > 0.0 ? 1.0 : -1.0) * (v * tau - tau * tau / (4.0 * k));
    }
    double End() const { return t0 + 2.0 * k * std::abs(rate); }
  };

  /// A pause from t to t1: the samples in it, and the coast of the stop
  /// before it while it lasts (in steps of at most 1 ms, so that the pose
  /// at any time follows it).
  void Rest(double t, double t1) {
    while (coast_.active && t < t1) {
      // Steps of at most 1 ms: the pose at any time (time_offset) is
      // interpolated linearly within a step, the coast is quadratic.
      double tb = std::min({t1, coast_.End(), t + 1e-3});
      if (next_sample_ < ts_.size() && ts_[next_sample_] > t && ts_[next_sample_] < tb) tb = ts_[next_sample_];
      const double step = coast_.Progress(tb) - coast_.Progress(t);
      StepRecord s;
      s.ta = t;
      s.tb = tb;
      s.start = pose_;
      if (coast_.turn) {
        s.left_m = -0.5 * step * truth_.true_wheelbase_m;
        s.right_m = 0.5 * step * truth_.true_wheelbase_m;
      } else {
        // Along the step's mid heading (the coast curves with stop_slide.arc).
        const double mid = pose_.theta + 0.5 * step * coast_.curvature;
        s.slide_x_m = step * std::cos(mid);
        s.slide_y_m = step * std::sin(mid);
        s.left_m = -0.5 * step * coast_.curvature * truth_.true_wheelbase_m;
        s.right_m = 0.5 * step * coast_.curvature * truth_.true_wheelbase_m;
      }
      pose_ = AdvancePose(pose_, s.left_m, s.right_m, truth_.true_wheelbase_m, 1.0, s.slide_x_m, s.slide_y_m);
      s.end = pose_;
      steps_.push_back(s);
      RecordSamplesUpto(tb);
      t = tb;
      if (tb >= coast_.End()) coast_.active = false;
    }
    RecordSamplesUpto(t1);
  }

  const RunPlan& plan_;
  const RunTruth& truth_;
  const Effects& fx_;
  const std::vector<double>& ts_;
  SimulatedRun& out_;
  const MotionBoundaries bounds_;
  NormalSource phase_rng_, stand_rng_, floor_rng_, swivel_rng_;
  WheelDisturbance disturbance_;
  const double nominal_per_tick_[2], true_per_tick_[2];
  const double slide_cos_, slide_sin_;
  // Wheel state: continuous position p (ticks, or nominal metres) and the
  // cumulative commanded nominal travel.
  double p_[2] = {0.0, 0.0};
  double commanded_[2] = {0.0, 0.0};
  Pose2 pose_;
  // castor_swivel: the last spot turn's sign since the last straight or arc
  // motion (0: none), and that motion's drive sign (0: none yet).
  int last_turn_sign_ = 0, last_drive_sign_ = 0;
  Coast coast_;
  std::vector<StepRecord> steps_;
  std::vector<Pose2> sample_pose_;
  std::vector<double> sample_p_[2];
  std::size_t next_sample_ = 0;
};

}  // namespace

SimulatedRun SimulateLoggedRun(const RunPlan& plan, const RunTruth& truth, std::uint64_t seed, std::uint64_t run_index,
                               const std::string& run_id, const std::string& direction) {
  if (!(truth.true_wheelbase_m > 0.0)) throw InvalidOptions("SimulateLoggedRun: true wheelbase must be > 0");
  const std::vector<double> ts = SampleTimes(plan);
  NormalSource gt_rng(StreamSeed(seed, run_index, kCampaignStreamGroundTruth));
  NormalSource run_time_rng(StreamSeed(seed, run_index, kCampaignStreamRunTime));
  // run_time_offset: this run's tau_i.
  // The ground truth's clock: each effect's GroundTruthDelay (a constant
  // offset, this run's own draw from run_time_rng).
  double delay = 0.0;
  for (const effects::Effect* e : effects::All())
    delay += e->GroundTruthDelay(
        truth.effects, [](void* rng) { return static_cast<NormalSource*>(rng)->Next(); }, &run_time_rng);
  SimulatedRun out;
  out.run.run = run_id;
  out.run.direction = direction;
  RunExecutor exec(plan, truth, seed, run_index, ts, out);
  exec.Execute();
  out.true_pose = exec.sample_pose();
  WriteLog(ts, exec.sample_pose(), exec.sample_p(), exec.steps(), truth, delay, gt_rng, out.run);
  return out;
}

}  // namespace umbmark::sim
