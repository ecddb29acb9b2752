// Reader for calibrated parameters in a `calibrate` JSON (see params_json.hpp).
#include "io/params_json.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "io/atomic_write.hpp"

namespace umbmark::io {

RobotParams ParseParamsJson(std::string_view text, const std::string& path, const RobotParams& recorded) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    std::size_t line = 1, col = 1;
    for (std::size_t i = 0; i + 1 < e.byte && i < text.size(); ++i) {
      if (text[i] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    throw InputError(path, line, col, "invalid JSON");
  } catch (const nlohmann::json::exception&) {
    // out_of_range: a number beyond double precision, e.g. 1e400
    throw InputError(path, "a number is out of range for double precision (e.g. 1e400)");
  }
  if (j.is_object() && j.contains("results")) {
    if (!j["results"].is_array() || j["results"].size() != 1)
      throw InputError(path, "a batch calibration result holds several calibrations; pass a single one");
    j = j["results"][0];
  }
  if (!j.is_object()) throw InputError(path, "expected a JSON object (a `umbmark calibrate --json` result)");
  const nlohmann::json* p = nullptr;
  if (j.contains("refined") && j["refined"].is_object() && j["refined"].contains("parameters"))
    p = &j["refined"]["parameters"];
  else if (j.contains("parameters"))
    p = &j["parameters"];
  if (!p || !p->is_object()) throw InputError(path, "no 'parameters' (or 'refined.parameters') object");
  RobotParams out = recorded;
  auto get = [&](const char* key, double& field) {
    if (!p->contains(key) || !(*p)[key].is_number())
      throw InputError(path, fmt::format("parameters.{} is missing or not a number", key));
    field = (*p)[key].get<double>();
  };
  get("wheelbase_m", out.wheelbase_m);
  get("wheel_diameter_left_m", out.wheel_diameter_left_m);
  get("wheel_diameter_right_m", out.wheel_diameter_right_m);
  if (p->contains("ticks_per_rev") && (*p)["ticks_per_rev"].is_number())
    out.ticks_per_rev = (*p)["ticks_per_rev"].get<double>();
  if (auto err = out.Check(); !err.empty()) throw InputError(path, "parameters: " + err);
  return out;
}

RobotParams ReadParamsJson(const std::string& path, const RobotParams& recorded) {
  return ParseParamsJson(ReadWholeFile(path), path, recorded);
}

}  // namespace umbmark::io
