// The ground truth's own noise, measured where no candidate effect reaches
// it: differences of the ground-truth pose inside standstills (every
// interval still by the encoders), away from the stop that begins them
// (settle_s: a clock offset, a slide, a settling or standstill_motion act
// there) and from the start that ends them (a castor kick may lead the first
// count by a sample). The baseline takes it as the ground truth's noise when
// the manifest does not state one (baseline.hpp), so an effect the baseline
// leaves out cannot widen the noise the gap test judges it against.
//
// Estimator (the structure function's plateau). For a stationary capture
// noise e_i of sd sigma and autocorrelation r(k), a difference over k
// samples has
//   D(k) = Var(e_{i+k} - e_i) = 2 sigma^2 (1 - r(k)).
// White noise: D(k) = 2 sigma^2 at every lag. Noise correlated over a few
// samples (a capture system's filter): r(1) > 0, so the sample-to-sample
// difference underestimates sigma by sqrt(1 - r(1)); D rises with k and
// levels off at 2 sigma^2 once r(k) ~ 0. So sigma(k) = sqrt(D(k) / 2) is
// measured at lags k = 1, 2, 4, ... (max_lag), each as the sd of the
// differences (their second moment about their mean), and the estimate is
// sigma(2k) for the
// first lag k whose doubling raises it by no more than plateau_tolerance
// (the plateau; for white noise sigma(2) ~ sigma(1)). Example: AR(1) noise
// with r(1) = 0.8, r(k) = 0.8^k: sigma(1) = 0.45 sigma, sigma(2) = 0.60,
// sigma(4) = 0.77, sigma(8) = 0.91, sigma(16) = 0.99 sigma; the first
// doubling within 15 % is 8 -> 16, so the estimate is sigma(16). Lags are
// used while they have min_differences. A drift inside the standstills (no
// plateau up to the longest lag) leaves the largest lag's value, reported
// as `plateau = false`: then sigma is an upper end (a single usable lag is
// reported the same way: the correlation was not checked).
//
// The sd, not a robust scale. The piece model is Gaussian in its second
// moments: a piece's covariance needs the capture noise's VARIANCE, whatever
// its shape. A motion capture's pose noise is not normal: a rigid body
// re-fitted to a changing subset of its markers jumps between a few poses
// (on the June OptiOdom sessions 0.3-0.6 mm and 4-7 mrad at once, and back
// a few samples later), on top of a fine jitter. 1.4826 x the median absolute
// deviation (the estimator before issue 28's gap lane, `robust`) measures the
// jitter's width and leaves the jumps out: s1 0.051 mm / 0.89 mrad, where
// the differences' sd gives 0.12 mm / 1.6 mrad, and the standstill pieces
// then scattered 4 x their predicted sd along-track. The robust value is
// still measured and reported beside it (robust_sigma_*); a nudge that stays
// (a step, not a jump and back) raises D(k) at every lag up to the step's
// distance from the ends, which the plateau rule sees as no plateau.
//
// Floor: a physics engine's ground truth (or a noise-free simulation) has
// standstills without any scatter (sigma 0), and a noise of 0 would make a
// standstill piece's covariance singular and every micrometre of numerical
// jitter a gap. The estimate is raised to floor_xy_m / floor_theta_rad
// (0.01 mm / 0.01 mrad, below any motion capture's noise; the 5th decimal of
// a pose in metres) and `floored` says so.
#pragma once

#include <string>

#include "diagnosis/pieces.hpp"

namespace umbmark::diag {

struct StandstillNoiseOptions {
  /// Time after a stop before samples count [s] (>= 0). Default 0.5.
  double settle_s = 0.5;
  /// Samples before the next motion's first count left out (>= 0). Default 1.
  int lead_samples = 1;
  /// Fewest differences per component and lag for a measurement (>= 3).
  /// Default 30 (the robust sd's sampling error is then about 20 %).
  int min_differences = 30;
  /// Longest lag of the structure function [samples] (>= 1; 1 is the plain
  /// sample-to-sample estimate). Default 16 (0.8 s at 20 Hz).
  int max_lag = 16;
  /// A doubling of the lag that raises sigma by at most this fraction is
  /// the plateau (> 0). Default 0.15.
  double plateau_tolerance = 0.15;
  /// Measure each lag robustly (1.4826 x the median absolute deviation,
  /// the width of the noise's core; the estimator before the gap lane)
  /// instead of by the differences' sd (the variance the piece covariances
  /// need; see the file comment). Default false.
  bool robust = false;
  /// Floors of the estimate [m], [rad] (>= 0). Default 1e-5 each.
  double floor_xy_m = 1e-5, floor_theta_rad = 1e-5;

  std::string Check() const;
};

struct StandstillNoise {
  bool measured = false;  ///< enough differences at lag 1 (min_differences)
  /// Per-sample sd at the plateau, floored [m], [rad].
  double sigma_xy_m = 0.0, sigma_theta_rad = 0.0;
  /// The sample-to-sample estimate (lag 1), unfloored [m], [rad].
  double lag1_sigma_xy_m = 0.0, lag1_sigma_theta_rad = 0.0;
  /// The robust scale at the same plateau lag (1.4826 x the MAD of the
  /// differences / sqrt 2), unfloored [m], [rad]. sigma / robust well above
  /// 1 (normal noise: 1 within sampling error) means a heavy-tailed capture
  /// noise (jumps).
  double robust_sigma_xy_m = 0.0, robust_sigma_theta_rad = 0.0;
  /// Lag of the plateau [samples], per component.
  int lag_xy = 1, lag_theta = 1;
  /// The structure function levelled off (false: still rising at the
  /// longest lag measured, sigma is an upper end).
  bool plateau_xy = true, plateau_theta = true;
  /// Raised to the floor (noise-free standstills).
  bool floored_xy = false, floored_theta = false;
  int differences = 0;  ///< heading differences at lag 1 (position: twice as many values, x and y)
  int standstills = 0;  ///< standstills that contributed
};

StandstillNoise MeasureStandstillNoise(const CampaignData& c, const StandstillNoiseOptions& options = {});

}  // namespace umbmark::diag
