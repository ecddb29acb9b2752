// Physical plausibility of fitted effects (see plausibility.hpp): each
// effect's own rule (lib/effects/<name>.cpp, Effect::Unphysical, NullFit).
#include "diagnosis/plausibility.hpp"

#include "effects/registry.hpp"

namespace umbmark::diag {

std::string UnphysicalFit(const std::string& effect, const std::map<std::string, double>& params, int runs,
                          const std::map<std::string, double>& se) {
  const effects::Effect* e = effects::Find(effect);
  return e == nullptr ? std::string() : e->Unphysical(params, runs, se);
}

std::string NullNoiseFit(const std::string& effect, const std::map<std::string, double>& params) {
  const effects::Effect* e = effects::Find(effect);
  return e == nullptr ? std::string() : e->NullFit(params);
}

}  // namespace umbmark::diag
