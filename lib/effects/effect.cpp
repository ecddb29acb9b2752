// The Effect base (see effect.hpp) and Effects::Check.
#include "effects/effect.hpp"

#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "effects/registry.hpp"

namespace umbmark::effects {

double Effect::TypicalSize(std::string_view name) const {
  for (const Parameter& p : d_.parameters)
    if (p.name == name) return p.typical;
  return 0.0;
}

std::string Effect::Check(const Effects& e) const {
  for (const Parameter& p : d_.parameters)
    if (p.field != nullptr && !std::isfinite(e.*p.field))
      return fmt::format("{}.{} = {} must be finite", d_.name, p.name, e.*p.field);
  return Range(e);
}

bool Effect::Active(const Effects& e) const {
  for (const Parameter& p : d_.parameters)
    if (p.field != nullptr && e.*p.field != 0.0) return true;
  return false;
}

std::string Effect::PlainProblem(const Params& /*p*/) const { return fmt::format("{} is off", d_.name); }

double Effect::Get(const Params& p, const char* name) {
  const auto it = p.find(name);
  return it == p.end() ? 0.0 : it->second;
}

double Effect::Size(const Params& p, const char* name) {
  const auto it = p.find(name);
  return it == p.end() ? std::numeric_limits<double>::infinity() : std::abs(it->second);
}

std::string Effect::HeadingJumpFloor(const Params& p, const CampaignScale& c, const char* name) {
  if (!(c.negligible > 0.0) || !(Size(p, name) < c.FloorRad())) return {};
  return fmt::format("heading kicks of {:.2f} mrad (below {:.2g} mrad)", 1e3 * Size(p, name), 1e3 * c.FloorRad());
}

std::string Effect::NoisePerEventTooLarge(const Params& p, const char* key) {
  if (!p.count(key) || !(Get(p, key) > 0.05)) return {};
  return fmt::format("{:.0f} mm of noise per event ({}): larger than any slip or settling; a ground-truth glitch or a "
                     "mismatched run is more likely",
                     1e3 * Get(p, key), key);
}

std::string Effect::FittedAtZero(const Params& p, const std::vector<std::pair<const char*, double>>& zero) {
  std::string values;
  for (const auto& [k, z] : zero) {
    const auto v = p.find(k);
    if (v == p.end() || !(std::abs(v->second) <= z)) return {};
    values += fmt::format("{}{} = 0", values.empty() ? "" : ", ", k);
  }
  return fmt::format("fitted at {}: it adds nothing, so what its fit gains is the other noise refitted beside it",
                     values);
}

std::string Effects::Check() const {
  for (const Effect* e : All())
    if (std::string why = e->Check(*this); !why.empty()) return why;
  return {};
}

bool Effects::Active(EffectKind kind) const { return Of(kind).Active(*this); }

std::vector<EffectKind> Effects::ActiveKinds() const {
  std::vector<EffectKind> out;
  for (const Effect* e : All())
    if (e->Describe().kind && e->Active(*this)) out.push_back(*e->Describe().kind);
  return out;
}

}  // namespace umbmark::effects
