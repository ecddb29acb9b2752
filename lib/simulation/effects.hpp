// The contract's unmodelled effects (interface.md, "Effects"), shared by the
// campaign simulator (which produces them) and the diagnosis (which fits
// them). Names and parameter names are part of the contract:
//
//   scale_error         s           both true wheel diameters (1 + s) x the model's
//   turn_scrub          k           spot turns: true heading change (1 - k) x what the
//                                   true wheel travel implies
//   direction_asymmetry a           a wheel turning backwards has (1 + a) x its
//                                   forward effective diameter
//   castor_kick         kappa       at every start from standstill (not a spot turn)
//                                   the true heading jumps +kappa (forward) / -kappa
//                                   (backward)
//   bump_outliers       rate, sigma per wheel, Poisson bumps with `rate` per metre of
//                                   travel, each adding N(0, sigma^2) m of travel
//   correlated_noise    rho         correlation of the left and right random wheel errors
//   parameter_drift     r           run i (0-based, campaign order): true right
//                                   diameter (1 + r i) x run 0's
//   gt_offset           dx, dy      ground truth reports the point (dx, dy) of the
//                                   robot frame instead of the axle midpoint
//   time_offset         tau         a ground-truth sample stamped t shows the true
//                                   pose at t - tau
//   standstill_motion   sigma_xy,   after every motion, while the encoders read still,
//                       sigma_theta the true pose moves by N(0, sigma_xy^2) m along each
//                                   robot axis and N(0, sigma_theta^2) rad in heading
//                                   (once per standstill; the simulator applies it as
//                                   the standstill begins)
//   motion_noise_floor  sigma       every motion between two standstills adds N(0,
//                                   sigma^2) m to each wheel's true travel, whatever its
//                                   length (the simulator: half the variance as the
//                                   motion starts, half as it stops)
//   run_time_offset     tau_sd      run i's ground truth stamped t shows the true pose
//                                   at t - tau_i, tau_i ~ N(0, tau_sd^2) per run
//   stop_slide          d, a        at every stop (a standstill follows) after a straight
//                                   or arc motion at speed v the chassis coasts on by
//                                   d v^2 m along its last direction of travel; after a
//                                   spot turn at rate w it turns on by a w^2 rad
//   castor_swivel       kappa       at the start of a straight or arc motion that follows
//                                   a spot turn the heading jumps kappa x the turn's sign
//                                   (ccw +1, cw -1); after a reversal of the drive
//                                   direction +-kappa with equal probability
//
// Two further effects are NOT in the contract; the blind validation benchmark
// uses them as "outside" effects that no listed effect mimics, to check that
// the diagnosis answers `unexplained` instead of a confident wrong name:
//
//   gt_yaw_misalignment delta       the ground truth's heading is the true heading
//                                   + delta (a motion-capture rigid body defined with
//                                   a yaw offset); its position is right
//   floor_slope         g, dir      a tilted floor: the robot slides g metres per
//                                   metre of wheel travel ((|l| + |r|)/2) towards the
//                                   direction `dir` [rad] of its start frame
//
// Three contract names are parameter errors of a model the user gives
// (`diagnose --baseline CAL.json`), candidates of the diagnosis only:
// wheelbase_error, diameter_ratio_error, wheel_noise_error.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace umbmark::sim {

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
  // Parameter errors of a given model (`diagnose --baseline`): contract
  // names, candidates of the diagnosis only; nothing the simulator produces
  // (simulate the robot with other parameters instead).
  kWheelbaseError,
  kDiameterRatioError,
  kWheelNoiseError,
};

/// Magnitudes of every effect; zero means absent. Field names follow the
/// contract's parameter names.
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
  double yaw_delta = 0.0;      ///< gt_yaw_misalignment.delta [rad] (outside)
  double slope_g = 0.0;        ///< floor_slope.g [m/m] (outside)
  double slope_dir = 0.0;      ///< floor_slope.dir [rad] (outside)

  /// Empty when valid, else a message naming the bad field, its value and the
  /// rule it broke (run-count dependent limits of parameter_drift are checked
  /// by the simulator).
  std::string Check() const;
  /// Whether the effect has a non-zero magnitude.
  bool Active(EffectKind kind) const;
  /// Active effects, in catalogue order.
  std::vector<EffectKind> ActiveKinds() const;
};

/// One parameter of an effect, with its field in Effects.
struct EffectParameter {
  std::string_view name;
  double Effects::*field;
  std::string_view unit;
};

struct EffectDescriptor {
  EffectKind kind;
  std::string_view name;
  std::vector<EffectParameter> parameters;
  bool in_contract = true;
  std::string_view definition;
  /// False for the parameter errors of `diagnose --baseline`.
  bool simulated = true;
};

/// All effects, contract ones first (in the contract's table order).
const std::vector<EffectDescriptor>& EffectCatalogue();
/// The contract's fourteen effects (those the simulator produces).
std::vector<EffectKind> ContractEffects();
/// The contract's parameter errors of a given model (`diagnose --baseline`):
/// wheelbase_error, diameter_ratio_error, wheel_noise_error.
std::vector<EffectKind> ParameterErrorEffects();
/// Whether `kind` is one of ParameterErrorEffects().
bool IsParameterError(EffectKind kind);
const EffectDescriptor& Describe(EffectKind kind);
const char* EffectToString(EffectKind kind);
std::optional<EffectKind> EffectFromString(std::string_view name);

/// Parses "NAME:k=v,k=v" (e.g. "gt_offset:dx=0.02,dy=-0.01") and sets those
/// parameters in `effects` (parameters not named keep their value, normally
/// zero). Throws InvalidOptions naming the spec and what is wrong: unknown
/// effect or parameter, a parameter given twice, a value that is not a finite
/// number, or no parameter at all.
void ParseEffectSpec(std::string_view spec, Effects& effects);

/// "NAME:k=v,..." for one effect's current parameters (round-trips through
/// ParseEffectSpec).
std::string EffectSpecString(EffectKind kind, const Effects& effects);

}  // namespace umbmark::sim
