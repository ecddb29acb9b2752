// What the simulator and the diagnosis' mean model ask of an effect at a
// motion's start, in each step, at a stop and while coasting after it
// (Effect::StartRun, Effect::StopCoast, Effect::PredictStop): the types of
// those hooks, so that the simulator (simulation/campaign_run.cpp) and the
// mean model (diagnosis/model.cpp) name no effect.
#pragma once

#include <memory>

#include "core/pose2.hpp"

namespace umbmark::effects {

/// Simulation: one motion of a run as the simulator executes it.
struct SimMotion {
  bool turn = false;             ///< a spot turn (else a straight or an arc)
  bool from_standstill = false;  ///< starts from a standstill (PlannedMotion::from_standstill)
  bool motion_start = false;     ///< begins a new motion (not a continuation)
  /// Where it meets standstills (the simulator's boundaries): it starts from
  /// one, it stops before one, and a lasting pause follows it (the run's
  /// end does not count).
  bool starts = false, stops = false, standstill_follows = false;
  int sign = 0;                      ///< its sign (spot turn: the turn's; else the drive direction)
  double left_m = 0.0, right_m = 0.0;  ///< its commanded nominal wheel travel [m]
};

/// Simulation: one step of a motion (one sample interval or less).
struct SimStep {
  bool first = false, last = false;  ///< the motion's first, last step
  /// |true wheel travel| of the step before any noise [m] (left, right).
  double mean_abs[2] = {0.0, 0.0};
  /// The step's bump counters (left, right; two ints the simulator adds to
  /// the run's counts): an effect that adds bumps counts them here.
  int* bumps = nullptr;
};

/// Simulation: the random numbers of one effect in one run, from its own
/// stream (Descriptor::sim_stream), so that an effect's draws never shift
/// another's.
class RandomSource {
 public:
  virtual double Normal() = 0;       ///< N(0, 1)
  virtual double Uniform() = 0;      ///< [0, 1)
  virtual double Exponential() = 0;  ///< mean 1

 protected:
  ~RandomSource() = default;
};

/// Simulation: one effect in one run, with its own state (Effect::StartRun).
/// The simulator calls every run's effects in catalogue order.
class RunEffect {
 public:
  virtual ~RunEffect() = default;
  /// As motion m begins: changes the true pose (a heading kick).
  virtual void MotionStart(const SimMotion& /*m*/, Pose2& /*pose*/) {}
  /// Adds to one step's true wheel travel [m] (left, right), after the
  /// wheels' own noise: bumps, slip where motions start and stop.
  virtual void StepTravel(const SimMotion& /*m*/, const SimStep& /*s*/, double (&/*travel*/)[2]) {}
  /// The chassis' own move over one step on top of the wheels' (world
  /// frame, [m]) from the step's true wheel travel: a drift downhill. False:
  /// none (dx, dy untouched).
  virtual bool StepDrift(const double (&/*travel*/)[2], double& /*dx*/, double& /*dy*/) { return false; }
  /// As the robot comes to a standstill after motion m: an instantaneous
  /// move in the robot frame (dx, dy [m], dtheta [rad]), e.g. settling.
  /// False: none.
  virtual bool AtStop(const SimMotion& /*m*/, double& /*dx*/, double& /*dy*/, double& /*dtheta*/) { return false; }
};

/// Simulation: a coast after a stop (Effect::StopCoast): from the stop,
/// uniform deceleration 1 / (2 k) from `rate` (signed speed [m/s] or turn
/// rate [rad/s]) until it rests after 2 k |rate| s, having covered k rate
/// |rate| (m along the heading, or rad of turn); a coast along the heading
/// turns by `curvature` rad per metre coasted.
struct SimCoast {
  double rate = 0.0, k = 0.0, curvature = 0.0;
};

/// Model prediction: the motion a stop ended with, for Effect::PredictStop.
struct StopMotion {
  bool turn = false;       ///< a spot turn
  double vl = 0.0, vr = 0.0;  ///< the true wheel speeds it ended with [m/s]
  double wheelbase = 0.0;  ///< the true wheelbase [m]
};

}  // namespace umbmark::effects
