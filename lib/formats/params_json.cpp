// Reader for calibrated parameters in a `calibrate` JSON (see params_json.hpp).
#include "formats/params_json.hpp"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "core/plausible_units.hpp"
#include "formats/file_text.hpp"

namespace umbmark::io {

namespace {
/// Line and column (1-based) of byte offset `at` of `text`.
std::pair<std::size_t, std::size_t> LineColumn(std::string_view text, std::size_t at) {
  std::size_t line = 1, col = 1;
  for (std::size_t i = 0; i < at && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return {line, col};
}

/// Byte offset of the first number token outside strings that overflows a
/// double, or npos.
std::size_t OverflowingNumber(std::string_view text) {
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
      continue;
    }
    if (c == '"') {
      in_string = true;
    } else if (c == '-' || (c >= '0' && c <= '9')) {
      std::size_t end = i;
      while (end < text.size() && std::strchr("+-.eE0123456789", text[end]) != nullptr) ++end;
      const std::string token(text.substr(i, end - i));
      if (!std::isfinite(std::strtod(token.c_str(), nullptr))) return i;
      i = end - 1;
    }
  }
  return std::string_view::npos;
}
}  // namespace

nlohmann::json ParseJsonDocument(std::string_view text, const std::string& path) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    const auto [line, col] = LineColumn(text, e.byte > 0 ? e.byte - 1 : 0);
    throw InputError(path, line, col, "invalid JSON");
  } catch (const nlohmann::json::exception&) {
    // out_of_range: a number beyond double precision, e.g. 1e400
    const std::size_t at = OverflowingNumber(text);
    if (at == std::string_view::npos)
      throw InputError(path, "a number is out of range for double precision (e.g. 1e400)");
    const auto [line, col] = LineColumn(text, at);
    throw InputError(path, line, col, "a number is out of range for double precision (e.g. 1e400)");
  }
}

std::string ImplausibleParams(const RobotParams& p) {
  if (auto e = ImplausibleValue("wheelbase_m", p.wheelbase_m); !e.empty()) return e;
  if (auto e = ImplausibleValue("wheel_diameter_left_m", p.wheel_diameter_left_m); !e.empty()) return e;
  return ImplausibleValue("wheel_diameter_right_m", p.wheel_diameter_right_m);
}

RobotParams ParseParamsJson(std::string_view text, const std::string& path, const RobotParams& recorded) {
  nlohmann::json j = ParseJsonDocument(text, path);
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
  if (auto err = ImplausibleParams(out); !err.empty()) throw InputError(path, "parameters: " + err);
  return out;
}

RobotParams ReadParamsJson(const std::string& path, const RobotParams& recorded) {
  return ParseParamsJson(ReadWholeFile(path), path, recorded);
}

}  // namespace umbmark::io
