// Shared command-line plumbing (see common.hpp).
#include "common.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "core/plausible_units.hpp"
#include "core/utf8.hpp"
#include "output/atomic_write.hpp"
#include "formats/manifest.hpp"
#include "formats/robot_toml.hpp"

namespace umbmark::cli {

void RobotFlags::Bind(CLI::App& app) {
  app.add_option("--robot", robot_file, "Robot file (TOML): the parameters the odometry USED");
  app.add_option("--wheelbase", wheelbase_m, "Override wheelbase_m [m]")->check(Plausible("wheelbase_m"));
  app.add_option("--diameter-left", diameter_left_m, "Override wheel_diameter_left_m [m]")
      ->check(Plausible("wheel_diameter_left_m"));
  app.add_option("--diameter-right", diameter_right_m, "Override wheel_diameter_right_m [m]")
      ->check(Plausible("wheel_diameter_right_m"));
  app.add_option("--ticks-per-rev", ticks_per_rev, "Override ticks_per_rev (ticks per wheel revolution)")
      ->check(Plausible("ticks_per_rev"));
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
  nlohmann::json out = j;
  if (out.is_object() && !out.contains("warnings")) out["warnings"] = nlohmann::json::array();
  CommandOutputs().Write(path, DumpJson(out) + "\n");
}

void JsonFlag::EmitAndListOutputs(const nlohmann::json& j, std::vector<std::string> written) const {
  Emit(j);
  if (!path.empty() && !ToStdout()) written.push_back(path + " (JSON)");
  PrintWritten(written, PrintText());
}

namespace {
/// The number in `v` when all of it is one (finite), else nullopt.
std::optional<double> WholeNumber(const std::string& v) {
  try {
    std::size_t used = 0;
    const double x = std::stod(v, &used);
    if (used == v.size() && std::isfinite(x)) return x;
  } catch (const std::exception&) {
  }
  return std::nullopt;
}
}  // namespace

CLI::Validator NumberIn(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& v) -> std::string {
        const auto x = WholeNumber(v);
        if (!x || !(*x >= lo && *x <= hi)) return fmt::format("must be a number from {:g} to {:g} (got '{}')", lo, hi, v);
        return {};
      },
      fmt::format("NUMBER in [{:g}, {:g}]", lo, hi));
}

CLI::Validator Positive() {
  return CLI::Validator(
      [](std::string& v) -> std::string {
        const auto x = WholeNumber(v);
        if (!x || !(*x > 0.0)) return fmt::format("must be a finite number > 0 (got '{}')", v);
        return {};
      },
      "POSITIVE");
}

CLI::Validator Plausible(std::string_view key) {
  return CLI::Validator(
      [key](std::string& v) -> std::string {
        const auto x = WholeNumber(v);
        if (!x || !(*x > 0.0)) return fmt::format("must be a finite number > 0 (got '{}')", v);
        return ImplausibleValue(key, *x);
      },
      "POSITIVE");
}

CLI::Validator NonNegative() {
  return CLI::Validator(
      [](std::string& v) -> std::string {
        const auto x = WholeNumber(v);
        if (!x || !(*x >= 0.0)) return fmt::format("must be a finite number >= 0 (got '{}')", v);
        return {};
      },
      "NON-NEGATIVE");
}

CLI::Validator SeedValidator() {
  return CLI::Validator(
      [](std::string& v) -> std::string {
        const bool digits = !v.empty() && v.size() <= 20 && v.find_first_not_of("0123456789") == std::string::npos;
        if (!digits || (v.size() == 20 && v > "18446744073709551615")) {
          return fmt::format("the seed must be a whole number from 0 to 18446744073709551615 (got '{}')", v);
        }
        return {};
      },
      "SEED");
}

namespace {
/// Options and arguments that name a file or folder.
bool IsPathOption(const CLI::Option& opt) {
  static const char* const kLong[] = {"json", "report", "plot", "csv", "out", "params", "baseline", "ros2", "robot",
                                      "truth-out"};
  static const char* const kPositional[] = {"DATA", "MANIFEST", "CAL", "DIR", "BAG"};
  for (const auto& n : opt.get_lnames())
    for (const char* k : kLong)
      if (n == k) return true;
  if (!opt.get_positional()) return false;
  for (const char* k : kPositional)
    if (opt.get_name() == k) return true;
  return false;
}
}  // namespace

void CheckPathArguments(const CLI::App& app) {
  for (const CLI::Option* opt : app.get_options()) {
    if (opt->count() == 0 || !IsPathOption(*opt)) continue;
    const std::string name = opt->get_positional() ? opt->get_name() : "--" + opt->get_lnames().front();
    for (const auto& v : opt->results()) {
      if (v.empty()) {
        throw InvalidOptions(fmt::format("{}: empty path; give a file name{}", name,
                                         name == "--json" ? " or '-' for standard output" : ""));
      }
      if (v.find('\0') != std::string::npos) throw InvalidOptions(fmt::format("{}: the path contains a NUL byte", name));
    }
  }
  for (const CLI::App* sub : app.get_subcommands()) CheckPathArguments(*sub);
}

io::OutputSet& CommandOutputs() {
  static io::OutputSet set;
  return set;
}

void RegisterInputs(const std::vector<std::string>& inputs, const RobotFlags* robot) {
  io::OutputSet& outs = CommandOutputs();
  for (const auto& path : inputs) {
    outs.AddInput(path);
    if (!io::IsManifestPath(path)) continue;
    try {
      outs.AddManifestInputs(path, io::ReadManifest(path));
    } catch (const InputError&) {
      // reported by the command when it reads the manifest
    }
  }
  if (robot) outs.AddInput(robot->robot_file);
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

void PrintWritten(const std::vector<std::string>& files, bool to_stdout) {
  for (const auto& f : files) fmt::print(to_stdout ? stdout : stderr, "wrote {}\n", f);
}

}  // namespace umbmark::cli
