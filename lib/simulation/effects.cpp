// Effect catalogue, checks and "NAME:k=v,..." parsing (see effects.hpp).
#include "simulation/effects.hpp"

#include <charconv>
#include <cmath>
#include <limits>
#include <mutex>
#include <set>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "effects/registry.hpp"

namespace umbmark::sim {

// The catalogue of the registered effects, from the registry (in its
// order), rebuilt when an effect is added at run time (effects::Register:
// before any simulation or diagnosis runs, so no reference into it is held
// across a rebuild).
const std::vector<EffectDescriptor>& EffectCatalogue() {
  static std::mutex mutex;
  static std::vector<EffectDescriptor> catalogue;
  static std::size_t registered = 0;
  const std::lock_guard<std::mutex> lock(mutex);
  const std::vector<const ::umbmark::effects::Effect*>& all = ::umbmark::effects::All();
  if (registered != all.size()) {
    catalogue.clear();
    for (const ::umbmark::effects::Effect* e : all) {
      const ::umbmark::effects::Descriptor& d = e->Describe();
      if (!d.kind) continue;
      catalogue.push_back({*d.kind, d.name, d.parameters, d.in_contract, d.definition, !d.parameter_error});
    }
    registered = all.size();
  }
  return catalogue;
}

std::vector<EffectKind> ContractEffects() {
  std::vector<EffectKind> out;
  for (const auto& d : EffectCatalogue())
    if (d.in_contract && d.simulated) out.push_back(d.kind);
  return out;
}

std::vector<EffectKind> ParameterErrorEffects() {
  std::vector<EffectKind> out;
  for (const auto& d : EffectCatalogue())
    if (!d.simulated) out.push_back(d.kind);
  return out;
}

bool IsParameterError(EffectKind kind) { return !Describe(kind).simulated; }

const EffectDescriptor& Describe(EffectKind kind) {
  for (const auto& d : EffectCatalogue())
    if (d.kind == kind) return d;
  return EffectCatalogue().front();  // unreachable: every kind is catalogued
}

const char* EffectToString(EffectKind kind) { return Describe(kind).name.data(); }

std::optional<EffectKind> EffectFromString(std::string_view name) {
  for (const auto& d : EffectCatalogue())
    if (d.name == name) return d.kind;
  return std::nullopt;
}

void ParseEffectSpec(std::string_view spec, Effects& effects) {
  const auto fail = [&](const std::string& what) {
    throw InvalidOptions(fmt::format("--effect '{}': {}", spec, what));
  };
  const std::size_t colon = spec.find(':');
  const std::string_view name = spec.substr(0, colon);
  const auto kind = EffectFromString(name);
  if (!kind) {
    std::string known;
    for (const auto& d : EffectCatalogue()) known += (known.empty() ? "" : ", ") + std::string(d.name);
    fail(fmt::format("unknown effect '{}' (known: {})", name, known));
  }
  const EffectDescriptor& d = Describe(*kind);
  if (!d.simulated)
    fail(fmt::format("'{}' is a parameter error that `diagnose --baseline` names, not an effect the simulator "
                     "produces: simulate the robot with other parameters instead (E_d, E_b, k_L, k_R)",
                     d.name));
  if (colon == std::string_view::npos || colon + 1 >= spec.size())
    fail(fmt::format("no parameters; expected {}:{}=VALUE,...", d.name, d.parameters.front().name));
  std::string_view rest = spec.substr(colon + 1);
  std::set<std::string_view> seen;
  while (!rest.empty()) {
    const std::size_t comma = rest.find(',');
    const std::string_view item = rest.substr(0, comma);
    rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
    const std::size_t eq = item.find('=');
    if (eq == std::string_view::npos) fail(fmt::format("'{}' is not KEY=VALUE", item));
    const std::string_view key = item.substr(0, eq), value = item.substr(eq + 1);
    const EffectParameter* param = nullptr;
    for (const auto& p : d.parameters)
      if (p.name == key) param = &p;
    if (param == nullptr) {
      std::string known;
      for (const auto& p : d.parameters) known += (known.empty() ? "" : ", ") + std::string(p.name);
      fail(fmt::format("{} has no parameter '{}' (its parameters: {})", d.name, key, known));
    }
    if (!seen.insert(key).second) fail(fmt::format("parameter '{}' given twice", key));
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
    if (ec != std::errc() || ptr != value.data() + value.size() || !std::isfinite(v)) {
      // The allowed range, where Check states one that NaN fails.
      Effects probe;
      probe.*(param->field) = std::numeric_limits<double>::quiet_NaN();
      const std::string range = probe.Check();
      const std::size_t must = range.find(" must be ");
      fail(fmt::format("{} = '{}' is not a finite number{}", key, value,
                       range.starts_with(fmt::format("{}.{} ", d.name, key)) && must != std::string::npos &&
                               range.find("must be finite") == std::string::npos
                           ? ";" + range.substr(must)
                           : std::string()));
    }
    effects.*(param->field) = v;
  }
  if (seen.empty()) fail("no parameters");
  // The effect's own range (the rest of Check is the caller's business).
  if (const std::string e = effects.Check(); e.starts_with(std::string(d.name) + ".")) fail(e);
}

std::string EffectSpecString(EffectKind kind, const Effects& effects) {
  const EffectDescriptor& d = Describe(kind);
  std::string out(d.name);
  char sep = ':';
  for (const auto& p : d.parameters) {
    out += fmt::format("{}{}={}", sep, p.name, effects.*(p.field));
    sep = ',';
  }
  return out;
}

}  // namespace umbmark::sim
