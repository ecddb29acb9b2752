// How a wheel rests within its encoder tick when the controller stops a
// motion, read from the contract ("Commanded motion": the controller stops
// each leg or turn when its odometry says the target is reached; encoders
// count whole ticks of true wheel rotation).
//
// The odometry changes only when a count changes, so at the stop instant
// the last count, of one wheel (the trigger), has just completed the
// target: that wheel rests at its tick edge (phase u = 0, measured from the
// edge against the direction of motion). What the other wheel does depends
// on how the controller drives the wheels:
//   kWheelEdge  each wheel is driven to its own count target and stops on
//               its own tick edge: u_L = u_R = 0 (umbmark simulate);
//   kBody       the robot stops as a whole when its odometry crosses the
//               target: the other wheel rests anywhere in its tick,
//               u ~ U(0, 1). Either wheel's last count can complete a
//               straight leg or a spot turn (each moves the odometry by
//               about half a tick's worth), so each is the trigger with
//               probability 1/2.
// Under kBody, per wheel (tick units): E[u] = 1/4, E[u^2] = 1/6,
//   Var(u) = 5/48, Cov(u_L, u_R) = E[u_L u_R] - 1/16 = -1/16
// (one of the two is always 0). A wheel's count error is
// e = s t (u - 1/4) with s = +-1 its direction and t its tick [m].
// The diagnosis fits the baseline under both readings and keeps the one
// with the higher likelihood (diagnose.cpp); both have the same free
// parameters.
#pragma once

#include <utility>

#include "diagnosis/pieces.hpp"

namespace umbmark::diag {

const char* StopModelToString(StopModel m);

/// Moments of the rest phase u at a joint stop under kBody (tick units).
struct BodyStopMoments {
  static constexpr double kMean = 0.25;             ///< E[u]
  static constexpr double kVar = 5.0 / 48.0;        ///< Var(u) per wheel
  static constexpr double kCov = -1.0 / 16.0;       ///< Cov(u_L, u_R)
};

/// True when some run has a joint stop of both wheels with encoder counts
/// (only then do the two readings differ).
bool HasJointStops(const CampaignData& c);

/// The campaign with the kBody reading at every joint stop: the wheel
/// travel moves by s t / 4, the count errors get the variances and
/// covariance above, and the intervals are annotated again. `c` must be in
/// the kWheelEdge reading (as BuildCampaign makes it).
CampaignData WithBodyStops(const CampaignData& c);

/// One draw of the two wheels' count errors [m] at a joint stop under
/// kBody, from two independent uniform(0, 1) numbers (which wheel triggers,
/// where the other rests); s_* are the directions, t_* the ticks.
std::pair<double, double> DrawBodyStop(double coin, double u, int s_left, int s_right, double tick_left_m,
                                       double tick_right_m);

}  // namespace umbmark::diag
