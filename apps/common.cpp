// Shared command-line plumbing (see common.hpp).
#include "common.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "io/atomic_write.hpp"
#include "io/robot_toml.hpp"

namespace umbmark::cli {

void RobotFlags::Bind(CLI::App& app) {
  app.add_option("--robot", robot_file, "Robot file (TOML): the parameters the odometry USED")
      ->check(CLI::ExistingFile);
  app.add_option("--wheelbase", wheelbase_m, "Override wheelbase_m [m]")->check(CLI::PositiveNumber);
  app.add_option("--diameter-left", diameter_left_m, "Override wheel_diameter_left_m [m]")
      ->check(CLI::PositiveNumber);
  app.add_option("--diameter-right", diameter_right_m, "Override wheel_diameter_right_m [m]")
      ->check(CLI::PositiveNumber);
  app.add_option("--ticks-per-rev", ticks_per_rev, "Override ticks_per_rev (ticks per wheel revolution)")
      ->check(CLI::PositiveNumber);
}

bool RobotFlags::Given() const {
  return !robot_file.empty() || wheelbase_m || diameter_left_m || diameter_right_m || ticks_per_rev;
}

RobotParams RobotFlags::Resolve(const std::optional<RobotParams>& base) const {
  RobotParams p;
  bool have_file = false;
  if (!robot_file.empty()) {
    p = io::ReadRobotToml(robot_file);
    have_file = true;
  } else if (base) {
    p = *base;
    have_file = true;
  }
  if (wheelbase_m) p.wheelbase_m = *wheelbase_m;
  if (diameter_left_m) p.wheel_diameter_left_m = *diameter_left_m;
  if (diameter_right_m) p.wheel_diameter_right_m = *diameter_right_m;
  if (ticks_per_rev) p.ticks_per_rev = *ticks_per_rev;
  if (!have_file && !(wheelbase_m && diameter_left_m && diameter_right_m)) {
    throw InvalidOptions(
        "robot parameters missing: give --robot R.toml, a campaign manifest, or all of "
        "--wheelbase, --diameter-left, --diameter-right");
  }
  if (auto err = p.Check(); !err.empty()) throw InvalidOptions("robot: " + err);
  return p;
}

void JsonFlag::Bind(CLI::App& app) {
  app.add_option("--json", path, "Write the machine-readable result to FILE ('-' = stdout, JSON only)");
}

void JsonFlag::Emit(const nlohmann::json& j) const {
  if (path.empty()) return;
  const std::string text = j.dump(2) + "\n";
  if (ToStdout()) {
    std::fwrite(text.data(), 1, text.size(), stdout);
    std::fflush(stdout);
  } else {
    io::WriteFileAtomically(path, text);
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

std::string TaggedPath(const std::string& path, const std::string& tag) {
  std::filesystem::path p(path);
  const std::string stem = p.stem().string(), ext = p.extension().string();
  return (p.parent_path() / (stem + "-" + tag + ext)).string();
}

}  // namespace umbmark::cli
