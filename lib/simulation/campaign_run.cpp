// Run simulator of the campaign generator (see campaign_run.hpp).
#include "simulation/campaign_run.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "core/errors.hpp"
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
/// travel) and ground truth with gt_offset, time_offset, gt_yaw_misalignment
/// and measurement noise (from gt_rng); run_tau: this run's
/// run_time_offset tau_i, added to time_offset's tau.
void WriteLog(const std::vector<double>& ts, const std::vector<Pose2>& sample_pose,
              const std::vector<double> (&sample_p)[2], const std::vector<StepRecord>& steps, const RunTruth& truth,
              double run_tau, NormalSource& gt_rng, TrajectoryRun& run) {
  const Effects& fx = truth.effects;
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
    const double shift = fx.time_tau + run_tau;
    const Pose2 q = shift != 0.0 ? PoseAt(steps, ts[j] - shift, truth.true_wheelbase_m) : sample_pose[j];
    const double c = std::cos(q.theta), s = std::sin(q.theta);
    const double nx = gt_rng.Next(), ny = gt_rng.Next(), nt = gt_rng.Next();
    run.gt_x_m[j] = q.x + c * fx.gt_dx - s * fx.gt_dy + truth.gt_sigma_xy_m * nx;
    run.gt_y_m[j] = q.y + s * fx.gt_dx + c * fx.gt_dy + truth.gt_sigma_xy_m * ny;
    run.gt_theta_rad[j] = q.theta + fx.yaw_delta + truth.gt_sigma_theta_rad * nt;
  }
}

}  // namespace

// Longer than 80 lines on purpose: one loop over the motions and their steps
// that shares the wheel positions, the pose and the sample cursor; the
// pieces with state of their own (sample times, wheel disturbance, logger,
// pose at any time) are the helpers above.
SimulatedRun SimulateLoggedRun(const RunPlan& plan, const RunTruth& truth, std::uint64_t seed, std::uint64_t run_index,
                               const std::string& run_id, const std::string& direction) {
  const Effects& fx = truth.effects;
  if (!(truth.true_wheelbase_m > 0.0)) throw InvalidOptions("SimulateLoggedRun: true wheelbase must be > 0");
  const std::vector<double> ts = SampleTimes(plan);

  NormalSource gt_rng(StreamSeed(seed, run_index, kCampaignStreamGroundTruth));
  NormalSource phase_rng(StreamSeed(seed, run_index, kCampaignStreamPhase));
  NormalSource stand_rng(StreamSeed(seed, run_index, kCampaignStreamStandstill));
  NormalSource floor_rng(StreamSeed(seed, run_index, kCampaignStreamMotionFloor));
  NormalSource run_time_rng(StreamSeed(seed, run_index, kCampaignStreamRunTime));
  // run_time_offset: this run's tau_i.
  const double run_tau = fx.run_tau_sd > 0.0 ? fx.run_tau_sd * run_time_rng.Next() : 0.0;
  // A motion between two standstills: starts at the run's first move or
  // after a pause that lasts; stops before such a pause (or the run's end).
  std::vector<char> motion_starts(plan.motions.size(), 0), motion_stops(plan.motions.size(), 0);
  {
    bool still = true;
    for (std::size_t k = 0; k < plan.motions.size(); ++k) {
      const PlannedMotion& m = plan.motions[k];
      if (m.pause) {
        if (m.duration_s > 0.0) still = true;
        continue;
      }
      motion_starts[k] = still;
      still = false;
      std::size_t q = k + 1;
      while (q < plan.motions.size() && plan.motions[q].pause && !(plan.motions[q].duration_s > 0.0)) ++q;
      motion_stops[k] = q == plan.motions.size() || plan.motions[q].pause;
    }
  }
  // standstill_motion applies only when a standstill follows.
  auto standstill_follows = [&](std::size_t k) {
    for (std::size_t q = k + 1; q < plan.motions.size(); ++q) {
      if (!plan.motions[q].pause) return false;
      if (plan.motions[q].duration_s > 0.0) return true;
    }
    return false;
  };

  SimulatedRun out;
  TrajectoryRun& run = out.run;
  run.run = run_id;
  run.direction = direction;

  // Wheel state: continuous position p (ticks, or nominal metres) and the
  // cumulative commanded nominal travel.
  double p[2] = {0.0, 0.0};
  if (truth.ticks) {
    p[0] = phase_rng.Uniform();
    p[1] = phase_rng.Uniform();
  }
  out.phase_left = p[0];
  out.phase_right = p[1];
  const double nominal_per_tick[2] = {truth.nominal_per_tick_left, truth.nominal_per_tick_right};
  const double true_per_tick[2] = {truth.true_per_tick_left, truth.true_per_tick_right};
  WheelDisturbance disturbance(truth, seed, run_index);
  const double slide_cos = std::cos(fx.slope_dir), slide_sin = std::sin(fx.slope_dir);

  double commanded[2] = {0.0, 0.0};
  Pose2 pose;
  std::vector<StepRecord> steps;
  steps.reserve(ts.size() + 2 * plan.motions.size());
  std::vector<Pose2> sample_pose;
  sample_pose.reserve(ts.size());
  std::vector<double> sample_p[2];
  sample_p[0].reserve(ts.size());
  sample_p[1].reserve(ts.size());

  std::size_t next_sample = 0;
  auto record_samples_upto = [&](double t) {
    while (next_sample < ts.size() && ts[next_sample] <= t + 1e-9) {
      sample_pose.push_back(pose);
      sample_p[0].push_back(p[0]);
      sample_p[1].push_back(p[1]);
      ++next_sample;
    }
  };
  record_samples_upto(0.0);

  double t = 0.0;
  for (std::size_t mk = 0; mk < plan.motions.size(); ++mk) {
    const PlannedMotion& m = plan.motions[mk];
    const double t0 = t, t1 = t + m.duration_s;
    if (m.pause) {
      record_samples_upto(t1);
      t = t1;
      continue;
    }
    // Targets: the controller stops each wheel when its count reaches the
    // target count of the cumulative commanded travel.
    commanded[0] += m.left_m;
    commanded[1] += m.right_m;
    double p_end[2];
    for (int w = 0; w < 2; ++w) {
      if (truth.ticks) {
        const double target = std::round(commanded[w] / nominal_per_tick[w]);
        p_end[w] = EncoderStopPosition(target, std::floor(p[w]), p[w], kStopBelowTicks);
      } else {
        p_end[w] = commanded[w];
      }
    }
    const double dp_total[2] = {p_end[0] - p[0], p_end[1] - p[1]};
    // castor_kick: a start from standstill that is not a spot turn.
    if (m.from_standstill && m.cls != MotionClass::kTurn && fx.castor_kappa != 0.0) {
      pose.theta += (m.left_m + m.right_m >= 0.0 ? 1.0 : -1.0) * fx.castor_kappa;
    }
    const double heading_factor = m.cls == MotionClass::kTurn ? 1.0 - fx.scrub_k : 1.0;
    double ta = t0;
    double done = 0.0;  // fraction of the motion executed
    while (true) {
      double tb = t1;
      if (next_sample < ts.size() && ts[next_sample] < t1 - 1e-12 && ts[next_sample] > ta) tb = ts[next_sample];
      const double f_end = m.duration_s > 0.0 ? (tb - t0) / m.duration_s : 1.0;
      const bool last = tb >= t1;
      double travel[2];
      double dp[2];
      for (int w = 0; w < 2; ++w) {
        dp[w] = last ? p_end[w] - p[w] : (f_end - done) * dp_total[w];
        const double asym = dp[w] < 0.0 ? 1.0 + fx.asymmetry_a : 1.0;
        travel[w] = dp[w] * true_per_tick[w] * asym;
      }
      disturbance.Apply(travel, out);
      // motion_noise_floor: half its variance in the motion's first step,
      // half in its last (start and stop slip).
      if (fx.floor_sigma > 0.0) {
        const bool first_step = motion_starts[mk] && ta == t0, last_step = motion_stops[mk] && last;
        for (int w = 0; w < 2; ++w) {
          if (first_step) travel[w] += fx.floor_sigma * std::sqrt(0.5) * floor_rng.Next();
          if (last_step) travel[w] += fx.floor_sigma * std::sqrt(0.5) * floor_rng.Next();
        }
      }
      StepRecord s;
      s.ta = ta;
      s.tb = tb;
      s.start = pose;
      s.left_m = travel[0];
      s.right_m = travel[1];
      s.heading_factor = heading_factor;
      const double slide = fx.slope_g * 0.5 * (std::abs(travel[0]) + std::abs(travel[1]));
      s.slide_x_m = slide * slide_cos;
      s.slide_y_m = slide * slide_sin;
      pose = AdvancePose(pose, travel[0], travel[1], truth.true_wheelbase_m, heading_factor, s.slide_x_m,
                         s.slide_y_m);
      s.end = pose;
      steps.push_back(s);
      p[0] += dp[0];
      p[1] += dp[1];
      done = f_end;
      if (last) {
        p[0] = p_end[0];
        p[1] = p_end[1];
        // standstill_motion: the robot settles as the standstill begins (an
        // instantaneous step, so every still sample shows it).
        if ((fx.stand_sigma_xy > 0.0 || fx.stand_sigma_theta > 0.0) && motion_stops[mk] && standstill_follows(mk)) {
          StepRecord nudge;
          nudge.ta = nudge.tb = tb;
          nudge.start = pose;
          const double nx = fx.stand_sigma_xy * stand_rng.Next(), ny = fx.stand_sigma_xy * stand_rng.Next();
          const double nt = fx.stand_sigma_theta * stand_rng.Next();
          const double c = std::cos(pose.theta), sn = std::sin(pose.theta);
          pose = {pose.x + c * nx - sn * ny, pose.y + sn * nx + c * ny, pose.theta + nt};
          nudge.end = pose;
          steps.push_back(nudge);
        }
      }
      record_samples_upto(tb);
      if (last) break;
      ta = tb;
    }
    t = t1;
  }
  record_samples_upto(ts.back());

  out.true_pose = sample_pose;
  WriteLog(ts, sample_pose, sample_p, steps, truth, run_tau, gt_rng, run);
  return out;
}

}  // namespace umbmark::sim
