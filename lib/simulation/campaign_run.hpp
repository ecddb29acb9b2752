// One simulated run of a campaign: executes a plan of commanded motions on a
// true robot with the contract's effects, and records what a logger would:
// encoder counts per sample and (noisy) ground truth.
//
// Model (contract, "Commanded motion" and "Effects"):
//  - The controller ends each motion when the odometry (nominal parameters)
//    says the target is reached. With encoders, wheel w sits at continuous
//    position p_w [ticks] and reads floor(p_w); it starts at a random phase
//    p_w(0) ~ U[0, 1); the target count of a motion is
//    T = round(cumulative commanded travel / nominal metres per tick), and the
//    wheel stops the instant its count reaches T (p = T moving forward, just
//    below T + 1 moving backward). Without ticks_per_rev, p_w is the nominal
//    travel itself (no quantisation) and the logger writes dist_*_m.
//  - Both wheels turn at a constant ratio during a motion (constant
//    curvature), each wheel's position linear in time.
//  - A wheel's true ground travel over a step is dp times its true travel per
//    tick: nominal metres per tick x c (c_L = 2/(E_d+1), c_R = 2/(1/E_d+1))
//    x (1 + s) [scale_error] x (1 + r i) [parameter_drift, right wheel, run i]
//    x (1 + a) when dp < 0 [direction_asymmetry]; plus white noise of
//    variance k^2 |travel| (Chong & Kleeman eq. 4) with left/right
//    correlation rho [correlated_noise]; plus N(0, sigma^2) per bump, bumps
//    arriving per wheel as a Poisson process in travelled distance
//    [bump_outliers].
//  - The pose advances by an exact constant-curvature arc per step (no
//    small-angle approximation) with wheelbase E_b b; inside on-the-spot
//    turns the heading change is (1 - k) times (r - l)/b_true [turn_scrub].
//    At the start of every motion that is not a spot turn and starts from
//    standstill, the heading jumps by +kappa (forward) or -kappa (backward)
//    [castor_kick]. At the start of a straight or arc motion that follows a
//    spot turn (with or without a pause) the heading jumps by kappa_s times
//    the turn's sign; after a reversal of the drive direction by +-kappa_s,
//    the sign drawn with equal probability [castor_swivel].
//  - At a stop (a motion's end followed by a lasting pause, or the run's
//    end), first the robot settles [standstill_motion], an instantaneous
//    step as the wheels stop; then the chassis coasts on [stop_slide]: by
//    d v|v| metres along the heading after a straight or arc motion at true
//    speed v (the axle midpoint's, at the motion's end), by a w|w| rad after
//    a spot turn at true rate w, decelerating uniformly at 1/(2 d) (1/(2 a))
//    as Coulomb friction does, so the coast takes 2 d |v| (2 a |w|) seconds
//    of the pause that follows; a motion that starts earlier ends it.
//  - Ground truth at sample time t is the true pose at t - tau
//    [time_offset] (before the start: the start pose; after the end: the
//    end pose), reported at the robot-frame point (dx, dy) [gt_offset], plus
//    white measurement noise N(0, sigma_xy^2) per axis and N(0,
//    sigma_theta^2) in heading.
//  - Outside effects (effects.hpp): floor_slope adds g (|l| + |r|)/2 metres
//    towards direction dir per step; gt_yaw_misalignment adds delta to the
//    reported heading.
//
// Steps are the pieces between sample times and motion boundaries, so every
// sample sees the exact state; the noise of a step is lumped at that step
// (steps are one sample interval at most: 50 ms at 20 Hz).
//
// Randomness: every run draws from its own streams StreamSeed(seed, run,
// stream) (rng.hpp), so a run depends only on the seed and its index in the
// campaign.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/runs.hpp"
#include "core/pose2.hpp"
#include "simulation/effects.hpp"
#include "simulation/effects_motion.hpp"

namespace umbmark::sim {

/// Random stream ids of the campaign simulator (rng.hpp StreamSeed). The
/// effects' own streams are their Descriptor::sim_stream (102, 105, 106 and
/// 108 are taken; an effect that declares none gets 0x10000 + its order).
enum CampaignStream : std::uint64_t {
  kCampaignStreamWheelNoise = 101,
  kCampaignStreamGroundTruth = 103,
  kCampaignStreamPhase = 104,
  kCampaignStreamRunTime = 107,
};

/// One commanded motion, or a pause.
struct PlannedMotion {
  bool pause = false;
  MotionClass cls = MotionClass::kStraight;  ///< moves only
  /// Commanded nominal wheel travel [m] (what the odometry measures).
  double left_m = 0.0, right_m = 0.0;
  double duration_s = 0.0;
  /// Starts from standstill: the first motion of the run, or a motion right
  /// after a pause of non-zero duration (a motion that follows another one
  /// back to back never does). A castor kick applies unless cls is kTurn.
  bool from_standstill = true;
  /// The step begins / ends its motion (a replayed run splits a motion
  /// into one step per sample interval): castor_swivel kicks at a motion's
  /// start, stop_slide acts at its end when a lasting pause follows.
  bool motion_start = true, motion_end = true;
  /// The motion's sign: straight / arc +1 forward, -1 backward; turn +1
  /// ccw, -1 cw. 0: from this step's travel.
  int sign = 0;
  /// Nominal wheel speeds at the motion's end [m/s] (stop_slide); NaN: the
  /// step's travel over its duration.
  double end_rate_left = std::numeric_limits<double>::quiet_NaN();
  double end_rate_right = std::numeric_limits<double>::quiet_NaN();
};

struct RunPlan {
  std::vector<PlannedMotion> motions;
  /// Sample times [s], starting at 0, strictly increasing; the last must not
  /// precede the end of the last motion. Empty: every 1/sample_rate_hz from 0
  /// until the plan ends.
  std::vector<double> sample_times;
  double sample_rate_hz = 20.0;
};

/// The true robot and effects as they act on one run.
struct RunTruth {
  /// Nominal metres per tick (ticks mode) or 1 (distance mode, no
  /// quantisation; p is then the nominal travel in metres).
  double nominal_per_tick_left = 1.0, nominal_per_tick_right = 1.0;
  bool ticks = false;
  /// True forward ground travel per unit of p, including c, (1 + s) and the
  /// run's drift factor.
  double true_per_tick_left = 1.0, true_per_tick_right = 1.0;
  double true_wheelbase_m = 0.0;
  double k_L = 0.0, k_R = 0.0;  ///< wheel noise [m^1/2]
  Effects effects;              ///< all other effect magnitudes
  double gt_sigma_xy_m = 0.0, gt_sigma_theta_rad = 0.0;
};

/// Everything about a simulated run (the CSV keeps only ticks and ground truth).
struct SimulatedRun {
  TrajectoryRun run;              ///< what the logger writes
  std::vector<Pose2> true_pose;   ///< true axle-centre pose at each sample time
  double phase_left = 0.0, phase_right = 0.0;  ///< encoder start phases [ticks]
  int bumps_left = 0, bumps_right = 0;
};

/// Executes `plan` on `truth`. `run_index` is the run's index in the campaign
/// (random streams). Throws InvalidOptions for an inconsistent plan.
SimulatedRun SimulateLoggedRun(const RunPlan& plan, const RunTruth& truth, std::uint64_t seed, std::uint64_t run_index,
                         const std::string& run_id, const std::string& direction);

}  // namespace umbmark::sim
