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

void BindRobot(CLI::App& app, api::RobotSource& robot) {
  app.add_option("--robot", robot.robot_file, "Robot file (TOML): the parameters the odometry USED");
  app.add_option("--wheelbase", robot.wheelbase_m, "Override wheelbase_m [m]")->check(Plausible("wheelbase_m"));
  app.add_option("--diameter-left", robot.diameter_left_m, "Override wheel_diameter_left_m [m]")
      ->check(Plausible("wheel_diameter_left_m"));
  app.add_option("--diameter-right", robot.diameter_right_m, "Override wheel_diameter_right_m [m]")
      ->check(Plausible("wheel_diameter_right_m"));
  app.add_option("--ticks-per-rev", robot.ticks_per_rev, "Override ticks_per_rev (ticks per wheel revolution)")
      ->check(Plausible("ticks_per_rev"));
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

std::string TaggedPath(const std::string& path, const std::string& tag) {
  std::filesystem::path p(path);
  const std::string stem = p.stem().string(), ext = p.extension().string();
  return (p.parent_path() / (stem + "-" + tag + ext)).string();
}

void PrintWritten(const std::vector<std::string>& files, bool to_stdout) {
  for (const auto& f : files) fmt::print(to_stdout ? stdout : stderr, "wrote {}\n", f);
}

}  // namespace umbmark::cli
