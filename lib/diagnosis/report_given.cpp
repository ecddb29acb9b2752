// JSON and text of a diagnosis against a given model (see report_given.hpp).
#include "diagnosis/report_given.hpp"

#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "diagnosis/diagnose.hpp"

namespace umbmark::diag {

void AddGivenModelJson(const DiagnoseSummary& s, nlohmann::json& j) {
  nlohmann::json corrections = nlohmann::json::array();
  for (const ParameterCorrection& c : s.corrections)
    corrections.push_back({{"effect", c.effect},
                           {"parameter", c.parameter},
                           {"given", c.given},
                           {"corrected", c.corrected},
                           {"unit", c.unit},
                           {"text", c.text}});
  j["corrections"] = corrections;
  const auto& g = s.baseline.given;
  if (!g) {
    j["baseline"]["given"] = nullptr;
    return;
  }
  j["baseline"]["given"] = {{"source", g->source},
                            {"wheelbase_m", g->params.wheelbase_m},
                            {"wheel_diameter_left_m", g->params.wheel_diameter_left_m},
                            {"wheel_diameter_right_m", g->params.wheel_diameter_right_m},
                            {"noise_given", g->noise_given},
                            {"k_L", g->noise_given ? nlohmann::json(g->k_L) : nlohmann::json(nullptr)},
                            {"k_R", g->noise_given ? nlohmann::json(g->k_R) : nlohmann::json(nullptr)}};
}

std::string GivenModelReport(const DiagnoseSummary& s) {
  const auto& g = s.baseline.given;
  if (!g) return {};
  std::string out = fmt::format(
      "5. Your simulation ({}): wheelbase {:.5f} m, wheel diameters {:.6f} / {:.6f} m, wheel noise {}\n", g->source,
      g->params.wheelbase_m, g->params.wheel_diameter_left_m, g->params.wheel_diameter_right_m,
      g->noise_given ? fmt::format("k_L = {:.3g}, k_R = {:.3g} m^1/2", g->k_L, g->k_R)
                     : fmt::format("not given (fitted: k_L = {:.3g}, k_R = {:.3g} m^1/2; give --kl/--kr to check it)",
                                   s.baseline.k_L, s.baseline.k_R));
  if (!s.corrections.empty()) {
    out += "  What to change:\n";
    std::string last;
    for (const ParameterCorrection& c : s.corrections) {
      if (c.text == last) continue;
      out += "    " + c.text + "\n";
      last = c.text;
    }
  } else if (s.verdict == "none") {
    out += "  Its parameters agree with the runs: nothing to change.\n";
  } else {
    out += "  No wrong parameter is named: the gap comes from elsewhere (see the verdict); its parameters may stay.\n";
  }
  return out;
}

}  // namespace umbmark::diag
