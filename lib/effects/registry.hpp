// All effects, by name and in catalogue order. The built-in effects are
// each one file of lib/effects/ ending in UMBMARK_EFFECT(Class); the build
// gathers those lines into a generated list (CMakeLists.txt), so no source
// file names them all and the static library keeps every one. Tests (or a
// plugin) can add an effect at run time with Register.
#pragma once

#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "effects/effect.hpp"

namespace umbmark::effects {

/// Every registered effect, in catalogue order (Descriptor::order, then
/// registration order): contract effects first in the contract's order.
const std::vector<const Effect*>& All();

/// The effect named `name`, or nullptr.
const Effect* Find(std::string_view name);

/// The first effect (catalogue order) whose Descriptor::mean_terms holds
/// `term` (effects::MeanTerm), or nullptr.
const Effect* WithMeanTerm(int term);

/// The built-in effect of kind `kind` (transitional, see values.hpp).
const Effect& Of(EffectKind kind);
/// The kind of an effect (nullopt only for one not registered yet).
std::optional<EffectKind> KindOf(const Effect& e);

/// Adds an effect at run time (a test's dummy effect), giving it a kind of
/// its own when it has none (EffectKind::kFirstRunTime, + 1, ...). Throws
/// InvalidOptions when its name is taken or empty. Not thread-safe: call
/// before any simulation or diagnosis runs.
void Register(std::unique_ptr<Effect> effect);

}  // namespace umbmark::effects
