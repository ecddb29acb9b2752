// Robot file reader (TOML, contract keys wheelbase_m, wheel_diameter_left_m,
// wheel_diameter_right_m, ticks_per_rev, and the optional robot_id string),
// also used for a manifest's [robot];
// a whole manifest given as robot file yields its [robot] table.
#include "formats/robot_toml.hpp"
#include "formats/robot_id.hpp"

#include <array>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "core/errors.hpp"
#include "core/plausible_units.hpp"
#include "core/utf8.hpp"
#include "formats/file_text.hpp"
#include "formats/toml_util.hpp"

namespace umbmark::io {
namespace {

// A robot id names the robot in reports: 1-64 bytes of UTF-8 text without
// control characters (a serial number, an asset tag).
std::string RobotIdProblem(const std::string& id) {
  if (id.empty() || id.size() > 64) return fmt::format("robot_id has {} bytes; it must have 1 to 64", id.size());
  if (!IsValidUtf8(id)) return "robot_id is not valid UTF-8";
  for (const char c : id)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return "robot_id contains a control character";
  return {};
}

// The table's robot_id, checked; empty when it has none.
std::string RobotIdOf(const toml::table& table, const std::string& name) {
  const toml::node* node = table.get("robot_id");
  if (node == nullptr) return {};
  std::string id = detail::StringValue(*node, "robot_id", name);
  if (const std::string problem = RobotIdProblem(id); !problem.empty()) detail::FailAt(name, node->source(), problem);
  return id;
}

constexpr std::array<std::string_view, 4> kKeys = {"wheelbase_m", "wheel_diameter_left_m", "wheel_diameter_right_m",
                                                   "ticks_per_rev"};

/// `is_root`: the table is a whole robot file (a missing key is then a
/// whole-file fault) rather than a manifest's [robot] table.
RobotParams RobotFromTableImpl(const toml::table& table, const std::string& name, bool is_root) {
  const std::string what = is_root ? "the robot file" : "[robot]";
  detail::RejectUnknownKeys(table, {kKeys[0], kKeys[1], kKeys[2], kKeys[3], "robot_id"}, what, name);

  RobotParams robot;
  double* const targets[3] = {&robot.wheelbase_m, &robot.wheel_diameter_left_m, &robot.wheel_diameter_right_m};
  for (std::size_t k = 0; k < 3; ++k) {
    const toml::node* node = table.get(kKeys[k]);
    if (node == nullptr) {
      const std::string message = fmt::format("missing key '{}' in {}", kKeys[k], what);
      if (is_root) throw InputError(name, message);
      detail::FailAt(name, table.source(), message);
    }
    *targets[k] = detail::NumberValue(*node, kKeys[k], name);
  }
  if (const toml::node* node = table.get(kKeys[3])) robot.ticks_per_rev = detail::NumberValue(*node, kKeys[3], name);
  RobotIdOf(table, name);  // checked here, read by ReadRobotId

  // Check() names the bad field first; report it at that key's value.
  if (const std::string problem = robot.Check(); !problem.empty()) {
    for (const auto key : kKeys) {
      const toml::node* node = table.get(key);
      if (node != nullptr && problem.starts_with(key) && problem.substr(key.size(), 3) == " = ") {
        detail::FailAt(name, node->source(), problem);
      }
    }
    throw InputError(name, problem);
  }
  // Unit mix-ups (a wheelbase of 200: millimetres), refused at the value.
  for (const auto key : kKeys) {
    const toml::node* node = table.get(key);
    if (node == nullptr) continue;
    if (const std::string problem = ImplausibleValue(key, detail::NumberValue(*node, key, name)); !problem.empty())
      detail::FailAt(name, node->source(), problem);
  }
  return robot;
}

}  // namespace

RobotParams RobotFromTable(const toml::table& table, const std::string& name) {
  return RobotFromTableImpl(table, name, /*is_root=*/false);
}

RobotParams ParseRobotToml(std::string_view text, const std::string& name) {
  const toml::table table = detail::ParseTomlText(text, name);
  // A campaign manifest (a [robot] table and experiments) in place of a
  // robot file: its [robot] table. A lone [robot] table stays an error.
  if (const toml::table* robot = table.get_as<toml::table>("robot"); robot != nullptr && table.contains("experiment"))
    return RobotFromTableImpl(*robot, name, false);
  return RobotFromTableImpl(table, name, /*is_root=*/true);
}

RobotParams ReadRobotToml(const std::string& path) { return ParseRobotToml(ReadWholeFile(path), path); }

std::string ReadRobotId(const std::string& path) {
  const toml::table table = detail::ParseTomlText(ReadWholeFile(path), path);
  if (const toml::table* robot = table.get_as<toml::table>("robot"); robot != nullptr && table.contains("experiment"))
    return RobotIdOf(*robot, path);
  return RobotIdOf(table, path);
}

}  // namespace umbmark::io
