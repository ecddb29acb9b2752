// The unmodelled effects as the simulator and its command line see them:
// the catalogue, "NAME:k=v,..." specs and their parsing. Each effect itself
// (its contract name, parameters, ranges, class, floors, plausibility,
// advice) is one file of lib/effects/ (effects/effect.hpp, registry.hpp);
// this catalogue is built from that registry, in its order.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "effects/effect.hpp"

namespace umbmark::sim {

using effects::EffectKind;
using effects::Effects;

/// One parameter of an effect, with its field in Effects.
using EffectParameter = effects::Parameter;

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
