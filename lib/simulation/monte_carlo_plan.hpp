// The simulated robot and the compiled motion plan the Monte Carlo engine
// executes.
//
// Model (the contract's baseline model; Chong & Kleeman section 6.1 for the
// noise): the robot's odometry uses the NOMINAL parameters; the controller
// ends each commanded segment when its odometry says the target is reached,
// so commanded wheel rotations are the nominal ones. The physical robot has
// true wheel diameters D_true = c * (1 + s) * D_nom, with c_L = 2/(E_d + 1),
// c_R = 2/(1/E_d + 1) (contract, "Precise points") and s = scale error, and
// a true wheelbase E_b * b_nom (TrueRobot, model/true_robot.hpp). Each segment is split into P equal
// partitions; in each, each wheel's ground travel is its mean true travel
// plus white noise of variance k^2 |travel| (eq. 4), and the pose advances
// by an exact constant-curvature arc (no small-angle approximation).
//
// Encoder quantisation (optional): a wheel at continuous position p [ticks]
// reads floor(p); it starts at a random phase p0 ~ U[0, 1); the controller
// stops a wheel's motion the instant its count reaches the target
// round(cumulative nominal travel / metres-per-tick), i.e. at p = T moving
// forward and just below p = T + 1 moving backward (EncoderStopPosition,
// model/true_robot.hpp). The odometry integrates
// whole ticks with the nominal parameters.
//
// Adding an effect later: give SimulationModel a field, and express the
// effect in CompilePlan (per-segment means, partitions, wheelbase) or as a
// per-run adjustment drawn from its own RNG stream (rng.hpp, Stream) in
// RunSetup; the hot kernel consumes only SimSegment / LaneSegment numbers.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/robot.hpp"
#include "error_models/path_spec.hpp"
#include "error_models/wheel_noise.hpp"
#include "core/pose2.hpp"
#include "model/true_robot.hpp"

namespace umbmark::sim {

struct SimulationModel {
  /// What the odometry uses (wheelbase, diameters; ticks_per_rev when
  /// quantise_encoders).
  RobotParams nominal;
  TrueRobot truth;
  /// Random wheel noise on the true ground travel (eq. 4).
  WheelNoise noise;
  /// Encoders count whole ticks (needs nominal.ticks_per_rev).
  bool quantise_encoders = false;
  /// Covariance of the true start pose around (0, 0, 0) (Chong & Kleeman
  /// Tables 3-6); sampled per run. Must be symmetric positive semidefinite.
  PoseCovariance initial_covariance = PoseCovariance::Zero();

  /// Empty when valid, else a message naming the bad field.
  std::string Check() const;
};

/// One commanded segment, compiled.
struct SimSegment {
  int partitions = 1;
  /// Mean true ground travel of each wheel over the segment [m] (with
  /// quantisation: for encoder phase 0; see SimPlan::phase_*).
  double left_m = 0.0, right_m = 0.0;
  /// What the odometry measures for the segment [m] (nominal metres).
  double odo_left_m = 0.0, odo_right_m = 0.0;
  /// Encoder counts at the end of the segment (quantised plans only).
  std::int64_t ticks_left = 0, ticks_right = 0;
  /// Continuous wheel positions [ticks] where the segment stops (quantised
  /// plans; for encoder start phase 0 -- a wheel that has not moved yet
  /// still sits at its phase).
  double stop_left_ticks = 0.0, stop_right_ticks = 0.0;
};

struct SimPlan {
  double true_wheelbase_m = 0.0;
  double nominal_wheelbase_m = 0.0;
  WheelNoise noise;
  std::vector<SimSegment> segments;
  PoseCovariance initial_covariance = PoseCovariance::Zero();
  /// Quantisation: true metres per tick, and the segment whose true travel
  /// is shortened by the random start phase (p0 ticks) for each wheel
  /// (-1: the wheel never moves, or no quantisation).
  bool quantised = false;
  double true_metres_per_tick_left = 0.0, true_metres_per_tick_right = 0.0;
  double nominal_metres_per_tick_left = 0.0, nominal_metres_per_tick_right = 0.0;
  int phase_segment_left = -1, phase_segment_right = -1;
  /// Final pose the odometry computes (deterministic for a plan).
  Pose2 odometry_final;

  /// Partitions summed over segments: the wheel steps of one run.
  std::int64_t StepsPerRun() const;
};

/// Compiles a commanded path (nominal wheel travels per segment) for a
/// model, each segment split into `partitions` partitions. Throws
/// InvalidOptions when the model or partitions (>= 1) are invalid.
SimPlan CompilePlan(const SimulationModel& model, const std::vector<WheelSegment>& commanded, int partitions);

}  // namespace umbmark::sim
