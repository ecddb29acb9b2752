// The parameter values of every effect (zero: absent) and the kinds by
// which the diagnosis' results and options still refer to an effect. Field
// names follow the contract's parameter names; each effect's file says
// which fields are its own (Parameter::field).
#pragma once

#include <string>
#include <vector>

namespace umbmark::effects {

/// Kinds of the built-in effects, in the catalogue's order (transitional:
/// no library file outside lib/effects names one, but the diagnosis' options
/// and results (DiagnoseOptions::effects, Candidate::effect,
/// ExplanationStep::effect), the simulator's catalogue (sim::Describe,
/// EffectFromString) and the tests still use a kind as an effect's id;
/// each effect's file gives its kind, Descriptor::kind).
enum class EffectKind {
  kScaleError,
  kTurnScrub,
  kDirectionAsymmetry,
  kCastorKick,
  kBumpOutliers,
  kCorrelatedNoise,
  kParameterDrift,
  kGtOffset,
  kTimeOffset,
  kStandstillMotion,
  kMotionNoiseFloor,
  kRunTimeOffset,
  kStopSlide,
  kCastorSwivel,
  // Outside the contract (blind benchmark only).
  kGtYawMisalignment,
  kFloorSlope,
  // Parameter errors of a given model (`diagnose --baseline`).
  kWheelbaseError,
  kDiameterRatioError,
  kWheelNoiseError,
  /// The first id Register gives an effect added at run time (the next one
  /// gets kFirstRunTime + 1, ...): a kind is an id, not a closed list.
  kFirstRunTime = 1000,
};

/// Magnitudes of every effect; zero means absent.
struct Effects {
  double scale_s = 0.0;        ///< scale_error.s
  double scrub_k = 0.0;        ///< turn_scrub.k
  double asymmetry_a = 0.0;    ///< direction_asymmetry.a
  double castor_kappa = 0.0;   ///< castor_kick.kappa [rad]
  double bump_rate = 0.0;      ///< bump_outliers.rate [1/m]
  double bump_sigma = 0.0;     ///< bump_outliers.sigma [m]
  double noise_rho = 0.0;      ///< correlated_noise.rho
  double drift_r = 0.0;        ///< parameter_drift.r [1/run]
  double gt_dx = 0.0;          ///< gt_offset.dx [m]
  double gt_dy = 0.0;          ///< gt_offset.dy [m]
  double time_tau = 0.0;       ///< time_offset.tau [s]
  double stand_sigma_xy = 0.0;     ///< standstill_motion.sigma_xy [m]
  double stand_sigma_theta = 0.0;  ///< standstill_motion.sigma_theta [rad]
  double floor_sigma = 0.0;        ///< motion_noise_floor.sigma [m]
  double run_tau_sd = 0.0;         ///< run_time_offset.tau_sd [s]
  double slide_d = 0.0;            ///< stop_slide.d [s^2/m]
  double slide_a = 0.0;            ///< stop_slide.a [s^2/rad]
  /// stop_slide's shape beyond the contract (0: the contract's slide): after
  /// an arc the heading turns on by arc w/v times the distance coasted (2:
  /// at the arc's rate through the coast, two locked wheels sliding
  /// forward); a backward coast is (1 + back) d v^2 (load on the castor).
  double slide_arc = 0.0;
  double slide_back = 0.0;
  double swivel_kappa = 0.0;       ///< castor_swivel.kappa [rad]
  /// castor_swivel.kappa_start [rad]: sd of the heading kick at a run's
  /// first start (an extension beyond the contract; 0: the contract's).
  double swivel_kappa_start = 0.0;
  /// castor_swivel.slip_start [m]: sd of the position slip along each robot
  /// axis at a run's first start (extension; 0: none).
  double swivel_slip_start = 0.0;
  /// castor_swivel.kappa_sd [rad]: sd of the kick after a spot turn around
  /// its mean kappa (extension; 0: none).
  double swivel_kappa_sd = 0.0;
  double yaw_delta = 0.0;      ///< gt_yaw_misalignment.delta [rad] (outside)
  double slope_g = 0.0;        ///< floor_slope.g [m/m] (outside)
  double slope_dir = 0.0;      ///< floor_slope.dir [rad] (outside)

  /// Empty when valid, else a message naming the bad field, its value and the
  /// rule it broke (each effect's Effect::Check, in catalogue order;
  /// run-count dependent limits of parameter_drift are checked by the
  /// simulator).
  std::string Check() const;
  /// Whether the effect has a non-zero magnitude (Effect::Active).
  bool Active(EffectKind kind) const;
  /// Active built-in effects, in catalogue order.
  std::vector<EffectKind> ActiveKinds() const;
};

}  // namespace umbmark::effects
