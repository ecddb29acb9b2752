// Stage "baseline" of `diagnose --baseline CAL.json [--kl K --kr K]`: the
// runs are compared with the model the user simulates with, not with one
// fitted to them. The given model is a `calibrate` JSON's parameters
// (formats/params_json.hpp: refined.parameters when present, else parameters:
// wheelbase_m, wheel_diameter_left_m, wheel_diameter_right_m) and, when
// given, the wheel noise k_L, k_R [m^1/2] (Chong & Kleeman, eq. 4:
// variance k^2 |travel| per wheel).
//
// In the diagnosis' parameters (model.hpp) relative to the campaign's
// recorded robot (b, D_L, D_R; the odometry's):
//   E_b = b_given / b
//   c_L = D_L,given / D_L,  c_R = D_R,given / D_R
//   E_d = c_R / c_L,  1 + s = (c_L + c_R) / 2
// (the model's c_L = 2/(E_d + 1), c_R = 2 E_d/(E_d + 1) times the scale
// 1 + s give back each wheel's own factor).
//
// Nothing of the mean is fitted. The wheel noise is held at the given k_L,
// k_R; without --kl/--kr it is fitted as in the default mode (and then
// wheel_noise_error cannot be named: the diagnosis has nothing to compare
// it with; the report prints the fitted k_L, k_R instead). The ground
// truth's noise comes from the manifest or is fitted, as in the default
// mode.
//
// The parameter errors are candidate effects like the contract's others:
//   wheelbase_error       E_b free               (1 parameter)
//   diameter_ratio_error  E_d free               (1 parameter)
//   wheel_noise_error     k_L, k_R free          (2 parameters)
// and the other effects are fitted on top of the given model with E_d, E_b
// held at its values, so that every candidate is measured against the same
// model.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "core/robot.hpp"
#include "diagnosis/baseline.hpp"
#include "simulation/effects.hpp"

namespace umbmark::diag {

/// The user's simulation model.
struct GivenModel {
  RobotParams params;   ///< wheelbase and wheel diameters the simulation uses
  std::string source;   ///< file they came from (for messages and reports)
  /// k_L, k_R given (--kl, --kr); else they are fitted.
  bool noise_given = false;
  double k_L = 0.0, k_R = 0.0;  ///< [m^1/2]

  /// Empty when valid, else what is wrong (positive, finite geometry; k_L,
  /// k_R >= 0 and finite, not both 0).
  std::string Check() const;
};

/// The given model's E_d, E_b and scale relative to `recorded`.
ParamVector GivenParams(const RobotParams& recorded, const RobotParams& given);

/// The baseline of the given model (nothing of the mean fitted; see the
/// file comment). `free` is empty.
/// options: where the ground truth's noise comes from (baseline.hpp).
BaselineFit FitGivenBaseline(const CampaignData& c, const MeanModel& model, const GivenModel& given,
                             const BaselineFitOptions& options = {});

/// Parameter errors that are candidates for this given model: wheelbase and
/// diameter ratio always, wheel noise when k_L, k_R are given.
std::vector<sim::EffectKind> GivenModelCandidates(const GivenModel& given);

/// Readable parameters of a parameter error (or of scale_error, relative to
/// the given model's own scale) from the raw fitted ones (E_b; E_d; k_L,
/// k_R as the candidate and explanation stages report them). Keys carry
/// their units:
///   wheelbase_error       wheelbase_m (what the runs show), wheelbase_given_m,
///                         error_mm (given - shown), relative_error
///   diameter_ratio_error  ratio (D_R / D_L the runs show), ratio_given,
///                         error_ppm ((given / shown - 1) 1e6),
///                         wheel_diameter_left_m, wheel_diameter_right_m
///                         (corrected, mean diameter kept)
///   wheel_noise_error     k_L, k_R (fitted), k_L_given, k_R_given,
///                         ratio_L, ratio_R (fitted / given)
/// Other effects' parameters pass unchanged.
std::map<std::string, double> DescribeGivenParams(sim::EffectKind kind, const std::map<std::string, double>& raw,
                                                  const RobotParams& recorded, const GivenModel& given);

/// Standard errors of DescribeGivenParams' error terms from those of the
/// raw parameters (E_b -> error_mm, relative_error; E_d -> error_ppm).
std::map<std::string, double> DescribeGivenParamErrors(sim::EffectKind kind,
                                                       const std::map<std::string, double>& raw_se,
                                                       const RobotParams& recorded, const GivenModel& given);

/// One wrong parameter of the user's simulation and what to set instead.
struct ParameterCorrection {
  std::string effect;     ///< wheelbase_error, diameter_ratio_error, wheel_noise_error
  std::string parameter;  ///< e.g. "wheelbase_m"
  double given = 0.0;     ///< the simulation's value
  double corrected = 0.0; ///< what the runs show
  std::string unit;       ///< "m", "m^1/2"
  std::string text;       ///< one sentence: what is wrong, by how much, what to set
};

/// The corrections a named parameter error asks for (from its described
/// parameters, DescribeGivenParams). For wheel_noise_error only the wheel(s)
/// whose |k_fit / k_given - 1| reaches `negligible` (the practical threshold,
/// explanation.hpp) get a correction; the text says the other k is consistent.
std::vector<ParameterCorrection> Corrections(sim::EffectKind kind, const std::map<std::string, double>& described,
                                             const GivenModel& given, double negligible);

}  // namespace umbmark::diag
