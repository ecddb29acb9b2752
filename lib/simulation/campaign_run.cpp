// Run simulator of the campaign generator (see campaign_run.hpp).
#include "simulation/campaign_run.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

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

/// One effect's random stream (Descriptor::sim_stream) for its hooks.
class EffectStream final : public effects::RandomSource {
 public:
  explicit EffectStream(std::uint64_t seed) : src_(seed) {}
  double Normal() override { return src_.Next(); }
  double Uniform() override { return src_.Uniform(); }
  double Exponential() override { return src_.Exponential(); }

 private:
  NormalSource src_;
};

/// The effects of one run: their per-run state (Effect::StartRun) with
/// their streams, and the factors and correlation they make of the wheels.
struct RunEffects {
  std::vector<std::unique_ptr<EffectStream>> streams;
  std::vector<std::unique_ptr<effects::RunEffect>> runs;
  const effects::Effect* coast = nullptr;  ///< the first whose StopCoast may answer (else none)
  double backward = 1.0;      ///< Effect::BackwardFactor, multiplied
  double turn_heading = 1.0;  ///< Effect::TurnHeadingFactor, multiplied
  double rho = 0.0;           ///< Effect::WheelNoiseCorrelation, summed
};

RunEffects StartEffects(const Effects& fx, std::uint64_t seed, std::uint64_t run_index) {
  RunEffects out;
  for (const effects::Effect* e : effects::All()) {
    if (!e->Simulated()) continue;
    out.backward *= e->BackwardFactor(fx);
    out.turn_heading *= e->TurnHeadingFactor(fx);
    out.rho += e->WheelNoiseCorrelation(fx);
    if (!e->Active(fx)) continue;
    const effects::Descriptor& d = e->Describe();
    const std::uint64_t id = d.sim_stream != 0 ? d.sim_stream : 0x10000u + static_cast<std::uint64_t>(d.order);
    auto stream = std::make_unique<EffectStream>(StreamSeed(seed, run_index, id));
    if (auto run = e->StartRun(fx, *stream)) {
      out.runs.push_back(std::move(run));
      out.streams.push_back(std::move(stream));
    }
  }
  return out;
}

/// Wheel noise (Chong & Kleeman eq. 4, left/right correlation rho of the
/// effects, Effect::WheelNoiseCorrelation) on each step's true wheel
/// travel, from the run's own stream.
class WheelNoise {
 public:
  WheelNoise(const RunTruth& truth, double rho, std::uint64_t seed, std::uint64_t run_index)
      : wheel_rng_(StreamSeed(seed, run_index, kCampaignStreamWheelNoise)),
        k_{truth.k_L, truth.k_R},
        rho_(rho),
        rho_c_(std::sqrt(std::max(0.0, 1.0 - rho_ * rho_))) {}

  /// Adds the noise of one step to travel[0] (left), travel[1] (right) [m]
  /// whose size before noise is mean_abs.
  void Apply(double (&travel)[2], const double (&mean_abs)[2]) {
    const double z0 = wheel_rng_.Next(), z1 = wheel_rng_.Next();
    travel[0] += k_[0] * std::sqrt(mean_abs[0]) * z0;
    travel[1] += k_[1] * std::sqrt(mean_abs[1]) * (rho_ * z0 + rho_c_ * z1);
  }

 private:
  NormalSource wheel_rng_;
  double k_[2];
  double rho_, rho_c_;
};

/// One executed step: enough to re-evaluate the pose at any time inside it.
struct StepRecord {
  double ta = 0.0, tb = 0.0;
  Pose2 start, end;
  double left_m = 0.0, right_m = 0.0;  ///< true ground travel (noise and bumps included)
  double heading_factor = 1.0;         ///< of the heading change (Effect::TurnHeadingFactor in spot turns)
  double slide_x_m = 0.0, slide_y_m = 0.0;
};

/// The true robot's step (TrueStep) plus a move of the chassis beside it
/// (Effect::StepDrift, a coast).
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
/// comes after it (the run's end does not count).
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
        effects_(StartEffects(truth.effects, seed, run_index)),
        phase_rng_(StreamSeed(seed, run_index, kCampaignStreamPhase)),
        noise_(truth, effects_.rho, seed, run_index),
        nominal_per_tick_{truth.nominal_per_tick_left, truth.nominal_per_tick_right},
        true_per_tick_{truth.true_per_tick_left, truth.true_per_tick_right} {
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
        motion_ = Motion(mk);
        for (auto& e : effects_.runs) e->MotionStart(motion_, pose_);
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

  /// What the effects' hooks see of motion mk.
  effects::SimMotion Motion(std::size_t mk) const {
    const PlannedMotion& m = plan_.motions[mk];
    effects::SimMotion sm;
    sm.turn = m.cls == MotionClass::kTurn;
    sm.from_standstill = m.from_standstill;
    sm.motion_start = m.motion_start;
    sm.starts = bounds_.starts[mk];
    sm.stops = bounds_.stops[mk];
    sm.standstill_follows = bounds_.standstill_follows[mk];
    sm.sign = MotionSign(m);
    sm.left_m = m.left_m;
    sm.right_m = m.right_m;
    return sm;
  }

  /// One step's true wheel travel: the wheels' true size (and a backward
  /// factor, Effect::BackwardFactor), their noise, then what the effects
  /// add (RunEffect::StepTravel: bumps, start / stop slip).
  void StepTravel(bool first_step, bool last, const double (&dp)[2], double (&travel)[2]) {
    for (int w = 0; w < 2; ++w) travel[w] = dp[w] * true_per_tick_[w] * (dp[w] < 0.0 ? effects_.backward : 1.0);
    int bumps[2] = {0, 0};
    effects::SimStep st;
    st.bumps = bumps;
    st.first = first_step;
    st.last = last;
    st.mean_abs[0] = std::abs(travel[0]);
    st.mean_abs[1] = std::abs(travel[1]);
    noise_.Apply(travel, st.mean_abs);
    for (auto& e : effects_.runs) e->StepTravel(motion_, st, travel);
    out_.bumps_left += bumps[0];
    out_.bumps_right += bumps[1];
  }

  /// The steps of one motion, from t0 to its end: one per sample interval.
  void RunSteps(std::size_t mk, double t0, const double (&p_end)[2]) {
    const PlannedMotion& m = plan_.motions[mk];
    const double t1 = t0 + m.duration_s;
    const double dp_total[2] = {p_end[0] - p_[0], p_end[1] - p_[1]};
    const double heading_factor = m.cls == MotionClass::kTurn ? effects_.turn_heading : 1.0;
    double ta = t0;
    double done = 0.0;  // fraction of the motion executed
    while (true) {
      double tb = t1;
      if (next_sample_ < ts_.size() && ts_[next_sample_] < t1 - 1e-12 && ts_[next_sample_] > ta) tb = ts_[next_sample_];
      const double f_end = m.duration_s > 0.0 ? (tb - t0) / m.duration_s : 1.0;
      const bool last = tb >= t1;
      double dp[2], travel[2];
      for (int w = 0; w < 2; ++w) dp[w] = last ? p_end[w] - p_[w] : (f_end - done) * dp_total[w];
      StepTravel(ta == t0, last, dp, travel);
      StepRecord s;
      s.ta = ta;
      s.tb = tb;
      s.start = pose_;
      s.left_m = travel[0];
      s.right_m = travel[1];
      s.heading_factor = heading_factor;
      Drift(travel, s.slide_x_m, s.slide_y_m);
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

  /// The chassis' move beside the wheels' over one step (the effects'
  /// RunEffect::StepDrift, added; 0 without).
  void Drift(const double (&travel)[2], double& x, double& y) {
    bool any = false;
    for (auto& e : effects_.runs) {
      double dx = 0.0, dy = 0.0;
      if (!e->StepDrift(travel, dx, dy)) continue;
      x = any ? x + dx : dx;
      y = any ? y + dy : dy;
      any = true;
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

  /// At the end of motion mk (time t): the effects' moves as the robot
  /// comes to rest (RunEffect::AtStop), then a coast (Effect::StopCoast).
  void StopEffects(std::size_t mk, double t) {
    const PlannedMotion& m = plan_.motions[mk];
    for (auto& e : effects_.runs) {
      double nx = 0.0, ny = 0.0, nt = 0.0;
      if (!e->AtStop(motion_, nx, ny, nt)) continue;
      const double c = std::cos(pose_.theta), sn = std::sin(pose_.theta);
      Jump({pose_.x + c * nx - sn * ny, pose_.y + sn * nx + c * ny, pose_.theta + nt}, t);
    }
    // A coast at the speed the motion ended with, through the pause that
    // follows (Coast).
    if (!m.motion_end || !bounds_.stops[mk]) return;
    const double duration = m.duration_s > 0.0 ? m.duration_s : 1.0;
    double rate[2] = {std::isfinite(m.end_rate_left) ? m.end_rate_left : m.left_m / duration,
                      std::isfinite(m.end_rate_right) ? m.end_rate_right : m.right_m / duration};
    for (int w = 0; w < 2; ++w)
      rate[w] *= true_per_tick_[w] / nominal_per_tick_[w] * (rate[w] < 0.0 ? effects_.backward : 1.0);
    for (const effects::Effect* e : effects::All()) {
      effects::SimCoast c;
      if (!e->Simulated() || !e->StopCoast(fx_, motion_.turn, rate[0], rate[1], truth_.true_wheelbase_m, c)) continue;
      coast_ = {};
      coast_.t0 = t;
      coast_.turn = motion_.turn;
      coast_.rate = c.rate;
      coast_.k = c.k;
      coast_.curvature = c.curvature;
      coast_.active = coast_.k > 0.0 && coast_.rate != 0.0;
      break;
    }
  }

  /// A coast after a stop (Effect::StopCoast): from t0, uniform deceleration 1 / (2 k)
  /// (Coulomb friction) from `rate` until it rests after 2 k |rate| s,
  /// having covered k rate |rate| (m along the heading, or rad of turn).
  struct Coast {
    bool active = false, turn = false;
    double t0 = 0.0, rate = 0.0, k = 0.0;
    double curvature = 0.0;  ///< heading turned per metre coasted
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
        // Along the step's mid heading (the coast may curve).
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
  RunEffects effects_;
  NormalSource phase_rng_;
  WheelNoise noise_;
  const double nominal_per_tick_[2], true_per_tick_[2];
  // Wheel state: continuous position p (ticks, or nominal metres) and the
  // cumulative commanded nominal travel.
  double p_[2] = {0.0, 0.0};
  double commanded_[2] = {0.0, 0.0};
  Pose2 pose_;
  effects::SimMotion motion_;  ///< the motion being executed (Motion)
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
