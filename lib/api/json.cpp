// JSON building blocks of the command results (see json.hpp).
#include "api/json.hpp"

#include <cmath>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "core/utf8.hpp"
#include "formats/file_text.hpp"

namespace umbmark::api {

nlohmann::json ReadJsonFile(const std::string& path) {
  const std::string text = io::ReadWholeFile(path);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(path, 0, e.byte, fmt::format("not valid JSON: {}", e.what()));
  }
}

nlohmann::json JsonNumber(double v) {
  if (!std::isfinite(v)) return nullptr;
  return v;
}

nlohmann::json JsonParams(const RobotParams& p) {
  nlohmann::json j = {{"wheelbase_m", p.wheelbase_m},
                      {"wheel_diameter_left_m", p.wheel_diameter_left_m},
                      {"wheel_diameter_right_m", p.wheel_diameter_right_m}};
  if (p.ticks_per_rev) j["ticks_per_rev"] = *p.ticks_per_rev;
  return j;
}

nlohmann::json JsonEvaluationRuns(const EvaluationSummary& s) {
  nlohmann::json runs = nlohmann::json::array();
  for (const auto& r : s.runs) {
    runs.push_back({{"experiment", r.experiment},
                    {"run", r.run},
                    {"direction", r.direction},
                    {"final_position_error_m", r.final_position_error_m},
                    {"max_position_error_m", r.max_position_error_m},
                    {"final_heading_error_rad", r.final_heading_error_rad},
                    {"max_heading_error_rad", r.max_heading_error_rad},
                    {"return_error", {r.return_error.x, r.return_error.y, r.return_error.theta}}});
  }
  return runs;
}

nlohmann::json JsonEvaluationSummary(const EvaluationSummary& s) {
  return {{"runs", s.runs.size()},
          {"mean_final_position_error_m", s.mean_final_position_error_m},
          {"max_final_position_error_m", s.max_final_position_error_m},
          {"mean_max_position_error_m", s.mean_max_position_error_m},
          {"max_max_position_error_m", s.max_max_position_error_m},
          {"mean_final_heading_error_rad", s.mean_final_heading_error_rad},
          {"max_final_heading_error_rad", s.max_final_heading_error_rad},
          {"mean_max_heading_error_rad", s.mean_max_heading_error_rad},
          {"max_max_heading_error_rad", s.max_max_heading_error_rad}};
}

namespace {
nlohmann::json EscapedStrings(const nlohmann::json& j) {
  if (j.is_string()) {
    const auto& s = j.get_ref<const std::string&>();
    return IsValidUtf8(s) ? j : nlohmann::json(EscapeInvalidUtf8(s));
  }
  if (j.is_array()) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& v : j) out.push_back(EscapedStrings(v));
    return out;
  }
  if (j.is_object()) {
    nlohmann::json out = nlohmann::json::object();
    for (auto it = j.begin(); it != j.end(); ++it) out[EscapeInvalidUtf8(it.key())] = EscapedStrings(it.value());
    return out;
  }
  return j;
}
}  // namespace

std::string DumpJson(const nlohmann::json& j, int indent) {
  try {
    return j.dump(indent);
  } catch (const nlohmann::json::type_error&) {
    return EscapedStrings(j).dump(indent);  // invalid UTF-8 somewhere: escape, then dump
  }
}

}  // namespace umbmark::api
